"""What kind of dataset a validated config block is: plain dictionaries, no analysis imports.

Read by the chain (:class:`ballbat.chain.DatasetSettings`), the studies' sweeps, the config's
memory rules and the workflow's target lists (:mod:`ballbat.workflow_inputs`), which must
stay cheap to import at every workflow start.
"""

from __future__ import annotations

__all__ = ["films", "renders"]


def renders(dataset: dict) -> bool:
    """Whether a validated dataset renders camera tracks (its render block's ``enabled``, default filled)."""
    return "render" in dataset and bool(dataset["render"]["enabled"])


def films(dataset: dict) -> bool:
    """Whether a validated dataset renders high-speed clips (``render.video``), tracked and reduced from the pixels."""
    return renders(dataset) and "video" in dataset["render"]
