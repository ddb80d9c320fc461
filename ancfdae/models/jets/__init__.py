"""Second-order forward differentiation ("jets") for the exact tangents of the element kernels."""
