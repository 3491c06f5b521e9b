"""The reference solver's time loop compiled whole (numba): the system compiled once into flat
arrays (:mod:`.system_arrays`), the one-step contact solve (:mod:`.contact_solve`), one step
(:mod:`.step`), the loop that advances and records N steps (:mod:`.loop`), and which scenes it
supports (:mod:`.support`). The Python :class:`~clearbench.ref_solver.stepper.MoreauJeanStepper`
is its oracle: the same kernels, called from Python once per step.
"""
