"""Helpers of the test suite: finite differences (numerics), toy models, small flying beams, a toy study."""
