"""``python -m woodcam.cli ARGS`` runs the ``woodcam`` command."""

import sys

from . import main

sys.exit(main())
