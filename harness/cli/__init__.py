"""The ``clearbench`` command line: one module per command, assembled by :mod:`.main`."""
