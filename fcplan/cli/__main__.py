"""``python -m fcplan.cli``: the same as the ``fcplan`` console script."""

import sys

from fcplan.cli.parser import main

if __name__ == "__main__":
    sys.exit(main())
