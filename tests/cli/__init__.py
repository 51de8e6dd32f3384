"""Tests of ballbat.cli, a module each (tests/cli/test_X.py tests src/ballbat/cli/X.py)."""
