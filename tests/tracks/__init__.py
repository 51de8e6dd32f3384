"""Tests of ballbat.tracks, a module each (tests/tracks/test_X.py tests src/ballbat/tracks/X.py)."""
