"""``python -m ancfdae``: the same as the ``ancfdae`` command."""
import sys

from ancfdae.cli import main

sys.exit(main())
