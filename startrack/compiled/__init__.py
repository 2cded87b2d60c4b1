"""The compiled layer: numba's set-up and kernel cache, the compiled sorts, kernels compiled ahead."""
