"""Tests of ballbat.pipeline, a module each (tests/pipeline/test_X.py tests src/ballbat/pipeline/X.py)."""
