"""``python -m woodcam ARGS`` runs the ``woodcam`` command (as ``python -m woodcam.cli``)."""

import sys

from .cli import main

sys.exit(main())
