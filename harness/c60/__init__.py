"""The C-60 against the paper: analysis of runs and the validation report."""
