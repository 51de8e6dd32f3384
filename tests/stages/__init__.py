"""Tests of ballbat.stages, a module each (tests/stages/test_X.py tests src/ballbat/stages/X.py)."""
