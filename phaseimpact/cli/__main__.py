"""``python -m phaseimpact.cli``: the console script ``phaseimpact``."""

import sys

from . import main

sys.exit(main())
