"""Studies made of many runs: sweeps, the stability suite, regression, benchmarks."""
