"""Algorithms kept in the test suite (registered by the tests that need them)."""
