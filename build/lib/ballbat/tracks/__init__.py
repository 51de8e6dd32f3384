"""Raw camera tracks: the measurement chain of Sec. II, from tracked pixels to reduced impacts.

* :mod:`.data` — camera and rig settings, tracks held as dense per-camera arrays.
* :mod:`.render` — synthetic tracks of both cameras from a synthetic experiment's truth.
* :mod:`.io` and :mod:`.validate` — a lab's ``tracks.csv``/``.nc`` and ``impacts.csv``, checked whole.
* :mod:`.reduce` — per-impact fits giving v_bat, v_ball, theta, omega with fitted uncertainties.
* :mod:`.qa` — figures a lab uses to eyeball its tracks and fits.

See docs/tracks.md.
"""
