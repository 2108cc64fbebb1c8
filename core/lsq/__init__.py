"""The least-squares engine: Gauss-Markov and Gauss-Helmert blocks, constraints,
statistics, data snooping and the diagnosis of non-observable parameters."""
