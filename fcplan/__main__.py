"""``python -m fcplan``: the same as the ``fcplan`` console script."""

import sys

from fcplan.cli import main

sys.exit(main())
