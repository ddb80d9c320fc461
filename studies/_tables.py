"""The studies' markdown tables: a table, its cells, and the note under it that names the cases that raised."""
from __future__ import annotations

import math

__all__ = ["markdown_table", "cell", "errors_note"]


def markdown_table(headers, rows) -> str:
    """A GitHub markdown table; floats printed with 4 significant digits."""
    def fmt(x):
        if isinstance(x, float):
            return f"{x:.4g}" if 1e-3 <= abs(x) < 1e4 or x == 0 else f"{x:.3e}"
        return str(x)
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(fmt(x) for x in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def cell(x, spec: str = ".3g") -> str:
    """A table cell: ``x`` formatted with ``spec``, or "-" when it is None or not finite."""
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def errors_note(errors: dict) -> str:
    """The line under a study's table that names the cases that raised ("" when none did)."""
    if not errors:
        return ""
    return "\nCases that raised (not in the table): " + "; ".join(f"{k}: {v}" for k, v in errors.items()) + "\n"
