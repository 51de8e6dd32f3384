"""The ``ballbat`` command (:func:`main`): one module per command, the parser in :mod:`.app`.

:mod:`.check` (``ballbat check``), :mod:`.fly`, :mod:`.summary`, :mod:`.import_tracks`,
:mod:`.track_video`, :mod:`.bat`, :mod:`.compare`, :mod:`.hit` and :mod:`.design`, each a
command; :mod:`.common` what they share (the examples of their help, the one-line parser,
numbers and ranges). A command that runs stages calls :mod:`ballbat.chain`.
"""

from .app import main, parser

__all__ = ["main", "parser"]
