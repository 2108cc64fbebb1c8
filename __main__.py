"""``python -m lidarphoto``: the core's command line (no QGIS needed)."""

from .core.cli import main

raise SystemExit(main())
