"""Helpers of the test suite: finite differences (numerics), toy models, a toy study."""
