"""``python -m qzs``: the ``qzs`` command."""
import sys

from qzs.cli import main

sys.exit(main())
