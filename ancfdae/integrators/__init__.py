"""Interchangeable time integrators; each consumes only the Model contract (design.md Sect. 5)."""
from ancfdae.integrators._newton import NewtonOptions, NewtonOutcome, NewtonSolver, NewtonStats

__all__ = ["NewtonOptions", "NewtonOutcome", "NewtonSolver", "NewtonStats"]
