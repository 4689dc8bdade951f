"""``python -m qzs``: the ``qzs`` command."""
import sys

from qzs.cli import main

if __name__ == "__main__":
    sys.exit(main())
