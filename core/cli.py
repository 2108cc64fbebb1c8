"""Command line ``lidarphoto`` (also ``python -m lidarphoto``): the processing algorithms
without QGIS, for batch work.

Subcommands carry the algorithm ids of the QGIS toolbox (``lidarphoto:trajectorytoeo`` ->
``lidarphoto trajectorytoeo``) and options carry its parameter names, lower-cased with dashes
(``LEVER_ARM`` -> ``--lever-arm``), with the same value formats. Outputs that only QGIS can
make (layers) are written as the CSV outputs instead.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from . import __version__
from .errors import LidarPhotoError


def _add_trajectory_to_eo(sub: argparse._SubParsersAction) -> None:
    from .trajectory_to_eo import MOUNT_CHOICES

    p = sub.add_parser(
        "trajectorytoeo",
        help="INS/GNSS trajectory + camera mount -> exterior orientation per image",
        description=(
            "Direct georeferencing. Reads a trajectory CSV (image_id, time, easting, northing, "
            "height or latitude, longitude, height, and roll, pitch, heading in degrees) and "
            "writes the exterior orientation (X Y Z in the mapping CRS, omega phi kappa in "
            "degrees relative to the grid frame at each image)."
        ),
    )
    p.add_argument("--input", required=True, help="trajectory CSV file")
    p.add_argument("--crs", required=True, help="mapping CRS (projected), e.g. EPSG:31983 or WKT")
    p.add_argument("--lever-arm", default="0,0,0", help="x,y,z in metres, body frame")
    p.add_argument(
        "--mount",
        default=MOUNT_CHOICES[0],
        help=f"nominal mount: {', '.join(MOUNT_CHOICES)} (or its index)",
    )
    p.add_argument("--mount-matrix", default="", help="9 numbers, R_c^b row-major (custom mount)")
    p.add_argument("--boresight", default="0,0,0", help="domega,dphi,dkappa in degrees")
    p.add_argument("--output-csv", default=None, help="EO CSV to write (default: stdout)")
    p.set_defaults(run=_run_trajectory_to_eo)


def _run_trajectory_to_eo(args: argparse.Namespace) -> int:
    from .trajectory_to_eo import run_trajectory_to_eo

    table = run_trajectory_to_eo(
        args.input,
        args.crs,
        lever_arm=args.lever_arm,
        mount=args.mount,
        mount_matrix=args.mount_matrix,
        boresight=args.boresight,
        output_csv=args.output_csv,
    )
    if args.output_csv:
        print(f"{len(table)} images -> {args.output_csv}")
    else:
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "eo.csv"
            table.to_csv(path)
            sys.stdout.write(path.read_text(encoding="utf-8"))
    return 0


_ALGORITHMS = (_add_trajectory_to_eo,)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="lidarphoto", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"lidarphoto {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="algorithm", metavar="ALGORITHM", required=True)
    for add in _ALGORITHMS:
        add(sub)
    return parser


def parameter_names(algorithm: str) -> list[str]:
    """The processing-style parameter names (``LEVER_ARM``) a subcommand accepts."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [
        a.dest.upper()
        for a in sub.choices[algorithm]._actions
        if a.option_strings and a.dest != "help"
    ]


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.run(args))
    except LidarPhotoError as exc:
        print(f"lidarphoto {args.algorithm}: error: {exc}", file=sys.stderr)
        return 2
