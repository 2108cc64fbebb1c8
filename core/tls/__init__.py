"""Terrestrial laser scanning: the polar observation model with additional parameters, station
registration and self-calibration, and targets (spheres, checkerboards) fitted in scans."""
