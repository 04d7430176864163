"""``python -m gtecat`` is the ``gtecat`` command."""

import sys

from .cli.main import main

sys.exit(main())
