"""FCLIB one-step contact problems: reading them, and our solvers against Siconos's."""
