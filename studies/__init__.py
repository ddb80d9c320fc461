"""Studies that reproduce the chapter's Sect. 5 and compare integrators.

Each module has ``run(**options) -> dict`` (the tests call it in quick mode)
and is run from the command line as ``ancfdae study NAME``.
"""
