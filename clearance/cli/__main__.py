"""``python -m clearance.cli``: the `clearance` command."""

import sys

from clearance.cli import main

sys.exit(main())
