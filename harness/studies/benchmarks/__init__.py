"""Benchmarks: they measure and return numbers, they assert nothing (tests assert behaviour).

``clearbench bench NAME`` runs one and prints its table (:mod:`clearbench.harness.cli.bench`,
``clearbench bench --list`` lists them). The modules here do the measuring, each on one subject:

- :mod:`.speed`: the reference engine's wall time (library scenes, full C-60 runs, the hybrid
  solver's Newton-first memory);
- :mod:`.kernel_speed`: the compiled kernels called directly (NSGS sweeps on FCLIB problems,
  the contact geometry);
- :mod:`.physics`: the reference engine against physics (expectation figures, impact
  localisation, the Flores slider-crank, scale invariance);
- :mod:`.clearance_ladder`: the clearance pendulum approaching the ideal pendulum;
- :mod:`.physics_table`: any engine's error against physics as Markdown tables;
- :mod:`.contact_cost`: any engine's cost per step as simultaneous contacts grow;
- :mod:`.siconos_crosscheck`: the reference solver against Siconos at equal steps.

To add a benchmark: a function here that returns rows (frozen dataclasses), and an entry in
:data:`clearbench.harness.cli.bench.BENCHMARKS` that parses its options and prints the rows.
Diagnostics of one tool live with that tool (``clearbench c60 angles``), not here.
"""
