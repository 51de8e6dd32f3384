"""``python -m ballbat.cli``: the ``ballbat`` command (:func:`ballbat.cli.main`)."""

import sys

from .app import main

if __name__ == "__main__":  # importing the module (a walk of the package) runs nothing
    sys.exit(main())
