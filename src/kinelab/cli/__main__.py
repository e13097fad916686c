"""``python -m kinelab.cli``: the same as the ``kinelab`` command."""

import sys

from kinelab.cli.main import main

sys.exit(main())
