"""Raw camera tracks: the measurement chain of Sec. II, from tracked pixels to reduced impacts.

* :mod:`.data` — camera and rig settings, tracks held as dense per-camera arrays.
* :mod:`.render` — synthetic tracks of both cameras from a synthetic experiment's truth.
* :mod:`.io` and :mod:`.validate` — a lab's ``tracks.csv``/``.nc`` and ``impacts.csv``, checked whole.
* :mod:`.formats` — the tracking tools' own files (Tracker ``.trk``/``.trz``, Kinovea ``.kva``, exported tables).
* :mod:`.reduce` — per-impact fits giving v_bat, v_ball, theta, omega with fitted uncertainties.

The figures a lab uses to eyeball its tracks and fits are in the plotting layer,
:mod:`ballbat.plotting_tracks`: nothing here imports matplotlib.

See docs/tracks.md.
"""
