"""``python -m ballbat``: the ``ballbat`` command (:func:`ballbat.cli.main`)."""

import sys

from .cli import main

sys.exit(main())
