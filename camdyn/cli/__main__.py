"""``python -m camdyn.cli``: the ``camdyn`` command."""
import sys

from .commands import main

sys.exit(main())
