"""What every ``ballbat`` command shares: the examples of their help, the one-line parser, numbers and ranges."""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path
from typing import NoReturn

from . import compare, design, hit, track_video

#: The config schema and the default property tables, shipped with the package (``data/`` links
#: to ``workflow/schemas/`` and ``config/`` of the checkout, so there is one copy of each).
DATA = Path(__file__).resolve().parent.parent / "data"

EXAMPLES = {
    "check": """examples:
  ballbat check data/mylab/impacts.csv
  ballbat check data/mylab/impacts.csv --bats data/mylab/bats.csv
  ballbat check config/examples/maple_impacts.csv --bats config/examples/maple_bats.csv
  ballbat check config/examples/hickory_impacts.csv --bats config/examples/hickory_bats.csv
  ballbat check config/examples/tracked_tracks.csv --kind tracks --impacts config/examples/tracked_impacts.csv
  ballbat check --kind tracks --config config/examples/tracked.yaml   (as the reduce rule: reduce, cross-check)""",
    "fly": """examples:
  ballbat fly --speed 103 --angle 27.5 --backspin 2500
  ballbat fly --speed 103 --angle 27.5 --backspin 2500 --method calculator --json
  ballbat fly --speed 95 --angle 30 --backspin 2200 --sidespin -500 --spray 15 --wind 0,10
  ballbat fly --csv balls.csv        (columns named like the options: speed, angle, backspin, ...)""",
    "import-tracks": """examples:
  ballbat import-tracks data/mylab/trk/ --points ball=ball,bat_tip=tip,dot_a=A,dot_b=B -o tracks.csv
  ballbat import-tracks W01_swing.trk W01_spin.kva --points ball=ball,bat_tip=tip,dot_a=A,dot_b=B -o W01.csv
  ballbat import-tracks data/mylab/tables/ --format tracker_table --units time=s,length=m,y=up \\
      --camera swing:fps=3000,m_per_px=0.00074 --camera spin:fps=1000,m_per_px=0.00125 --points ... -o tracks.csv
Files are named {impact_id}_{camera}.{ext} (camera: swing or spin; --pattern to change it).
Prints the camera settings found in the files as YAML; exits 1 when a file cannot be read.""",
    "bat": """examples:
  ballbat bat --length 34 --weight 32 --balance-point 23.0 --moi-6in 11200 --impact-from-tip 6 --diameter 2.6 --iz 11
  ballbat bat --length 34 --weight 32 --balance-point 23.0 --period 1.72 --pivot 6 --impact-from-knob 28 \\
      --diameter 2.6 --iz 11 --name hickory
Prints the bat in the paper's convention and the lab's, its centre of percussion and what each
measured value's uncertainty does to e_x; exits 1 when the values fail a bat row's checks.""",
    "summary": """examples:
  ballbat summary results/synthetic
  ballbat summary results/maple""",
}
EXAMPLES["track-video"] = track_video.EXAMPLE
EXAMPLES["compare"] = compare.EXAMPLE
EXAMPLES["hit"] = hit.EXAMPLE
EXAMPLES["design"] = design.EXAMPLE


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) and exit with status 2.

    A value that starts with ``-`` and a digit (``--elevation -1e6``, ``--wind -5,3``) or reads
    ``-inf``/``-nan`` is a value, not an option (argparse's own test misses exponents).
    """

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)

    def error(self, message: str) -> NoReturn:
        """Report ``message`` as one line on stderr and exit 2."""
        self.exit(2, f"{self.prog}: error: {message}\n")


def _schema_defaults() -> dict:
    """Return the defaults the config schema gives the air and the flight (the workflow's own)."""
    import yaml

    schema = yaml.safe_load((DATA / "config.schema.yaml").read_text())
    air = schema["properties"]["implications"]["properties"]["air"]["properties"]
    flight = schema["$defs"]["flight"]["properties"]
    tables = schema["properties"]["tables"]["properties"]
    return {
        "air": {k: v["default"] for k, v in air.items()},
        "flight": {k: v["default"] for k, v in flight.items()},
        "tables": {k: str(DATA / Path(v["default"]).name) for k, v in tables.items()},
        "limits": schema["$defs"],
    }


def _finite(text: str) -> float:
    """Parse a number that must be finite (``nan``, ``inf`` and ``1e400`` are not)."""
    try:
        val = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(val):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return val


def _range_problem(val: float, limits: dict, unit: str) -> str | None:
    """Return why ``val`` lies outside the schema's range ``limits`` (None when inside)."""
    if not math.isfinite(val):
        return f"{val!r} is not a finite number"
    lo, hi = limits.get("minimum"), limits.get("maximum")
    xlo, xhi = limits.get("exclusiveMinimum"), limits.get("exclusiveMaximum")
    below = (lo is not None and val < lo) or (xlo is not None and val <= xlo)
    above = (hi is not None and val > hi) or (xhi is not None and val >= xhi)
    if not (below or above):
        return None
    left = f"[{lo:g}" if lo is not None else f"({xlo:g}" if xlo is not None else "(-inf"
    right = f"{hi:g}]" if hi is not None else f"{xhi:g})" if xhi is not None else "inf)"
    about = limits.get("description", "")
    return f"{val:g} {unit} is outside {left}, {right} {unit}" + (f" ({about})" if about else "")
