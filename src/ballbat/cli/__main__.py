"""``python -m ballbat.cli``: the ``ballbat`` command (:func:`ballbat.cli.main`)."""

import sys

from .app import main

sys.exit(main())
