"""``python -m qzs``: the ``qzs`` command."""
from qzs.cli import console

if __name__ == "__main__":
    console()
