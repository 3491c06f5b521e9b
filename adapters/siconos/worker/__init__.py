"""Scripts run under Debian's /usr/bin/python3 (where Siconos imports). They import nothing
from clearbench; the parent side imports only :mod:`.geometry` (pure numpy)."""
