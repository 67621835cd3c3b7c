"""``python -m cloudprox``: the command-line interface."""

import sys

from cloudprox.cli import main

sys.exit(main())
