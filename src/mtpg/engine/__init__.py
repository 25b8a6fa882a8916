"""The execution engine: populations compiled to flat arrays and run by Numba kernels."""
