"""Whether the compiled kernels run: one decision for the whole package.

numba is a dependency; every ``_<name>_numba.py`` kernel module sits beside the numpy reference
it compiles (``_cardan_numba.py`` beside ``cardan.py``) and falls back to that reference where
``AVAILABLE`` is False.  ``SIM_CORE_NUMBA=0`` (read once, at import) forces the reference
paths everywhere: to check a kernel against its reference, or where numba is broken.
"""

from __future__ import annotations

import os

ENV = "SIM_CORE_NUMBA"
FORCED_OFF = os.environ.get(ENV, "1").strip().lower() in ("0", "off", "false", "no")

numba = None
if not FORCED_OFF:
    try:
        import numba
    except ImportError:          # pragma: no cover - numba is a dependency
        numba = None

AVAILABLE = numba is not None
