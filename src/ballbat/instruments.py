"""The calibration uncertainties a measured impacts file can state (config ``datasets.<name>.calibration``).

A leaf module (no imports), so that the tables and captions that name these sources
(:mod:`ballbat.compare`) need not import the systematics' machinery
(:mod:`ballbat.systematics`, which propagates them).
"""

#: source (the ``systematic`` coordinate's name) -> (config key, what; the key's unit).
INSTRUMENT_SOURCES = {
    "speed_scale": ("speed_scale_pct", "scale of the bat and ball speeds (calibration.speed_scale_pct, %)"),
    "spin_scale": ("spin_scale_pct", "scale of the spin (calibration.spin_scale_pct, %)"),
    "angle_offset": ("angle_offset_deg", "offset of the launch angle theta (calibration.angle_offset_deg, deg)"),
}
