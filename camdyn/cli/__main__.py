"""``python -m camdyn.cli``: the ``camdyn`` command."""
import sys

from .app import main

sys.exit(main())
