"""`python -m cirrus_farm`, the same as the `cirrus-farm` command."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
