"""Tests of ballbat.video, a module each (tests/video/test_X.py tests src/ballbat/video/X.py)."""
