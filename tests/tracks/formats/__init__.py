"""Tests of ballbat.tracks.formats, a module each (tests/tracks/formats/test_X.py)."""
