"""``python -m phantom_pin.cli``: the phantom-pin command."""

import sys

from phantom_pin.cli.app import main

if __name__ == "__main__":
    sys.exit(main())
