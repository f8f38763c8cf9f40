"""``python -m qrrt_circuits.cli``: the ``qrrt`` command."""

import sys

from . import main

sys.exit(main())
