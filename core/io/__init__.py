"""Readers and writers of the core's file formats (CSV tables, camera JSON, LAS/LAZ)."""
