"""Simulators with known truth: a town of roofs, calibration flights over it and images
rendered by ray casting (tests, benchmarks and the demo; not shipped in the plugin zip)."""
