"""Tolerance campaigns: a scene's parameters drawn from their laws, one isolated run per
sample on Dask, and capability statistics of the outputs (the C-60 study's Section 4).

- :mod:`.definition`: the campaign file (TOML) and its validation;
- :mod:`.designs`: sample i's inputs from (seed, design, i);
- :mod:`.execution`: planning and running the samples on Dask, resumably, into the store;
- :mod:`.results`: the samples' outputs as a table;
- :mod:`.statistics`: Cp, Cpk, Cc, PPM with confidence intervals; sensitivities;
- :mod:`.report`: the report section.
"""
