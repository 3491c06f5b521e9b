"""Scripts run under Debian's /usr/bin/python3 (where Siconos imports). Of clearbench they
import only the kernels, by path (:mod:`.project_kernels`); the parent side imports only
:mod:`.geometry` (the Siconos pair table and slots)."""
