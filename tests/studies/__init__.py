"""Tests of ballbat.studies, a module each (tests/studies/test_X.py tests src/ballbat/studies/X.py)."""
