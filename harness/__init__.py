"""Runner, metrics, sweeps, results store, report and command-line interface."""
