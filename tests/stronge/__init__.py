"""Tests of ballbat.stronge, a module each (tests/stronge/test_X.py tests src/ballbat/stronge/X.py)."""
