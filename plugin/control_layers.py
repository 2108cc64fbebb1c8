"""The picking dock's LiDAR control from QGIS layers: features -> core objects, read once.

Each feature of the roof plane (polygon), line and control point layers becomes a
:class:`~lidarphoto.core.photo.picking.ControlFeature` in the mapping CRS of the exterior
orientation (layers in another CRS are reprojected with ``QgsCoordinateTransform``), and
:class:`~lidarphoto.core.photo.picking_session.ControlSet` turns them into planes, lines and
control points (the plane maths is the core's). The plane, line and LCP tables of the
Calibration tab, when given, replace the objects of the same id (they carry the full
covariances). :class:`ControlLinks` remembers which feature each target id came from, for the
selection on the map.
"""

from __future__ import annotations

import numpy as np
from qgis.core import Qgis, QgsCoordinateTransform, QgsGeometry, QgsWkbTypes
from qgis.PyQt.QtCore import QVariant

from ..core.io.control import read_lcps_csv, read_lines_csv
from ..core.io.planes import read_planes_csv
from ..core.photo.control_features import ControlFeature, ControlSet

__all__ = ["KINDS", "ControlLinks", "layer_features", "read_control", "read_tables"]

#: the control kinds, in the order of the dock's layer choosers
KINDS = ("planes", "lines", "lcps")

if hasattr(Qgis, "GeometryType"):  # pragma: no cover - QGIS >= 3.30 / 4
    _POLYGON = Qgis.GeometryType.Polygon
else:  # QGIS 3.22-3.28 (scoped: PyQt6 has no unscoped enum values)
    _POLYGON = QgsWkbTypes.GeometryType.PolygonGeometry


def _vertices(geometry: QgsGeometry) -> np.ndarray:
    """(M, 3) vertices of a geometry (z = NaN when it has none)."""
    pts = [(v.x(), v.y(), v.z()) for v in geometry.vertices()]
    return np.array(pts, dtype=np.float64).reshape(-1, 3)


def _plain(value):
    """A field value as Python (None for NULL)."""
    if value is None or (isinstance(value, QVariant) and value.isNull()):
        return None
    return value


def layer_features(layer, crs, project) -> tuple[list[ControlFeature], list[int]]:
    """The features of a layer in the mapping CRS ``crs`` and their QGIS feature ids.

    The target id is the ``id`` field as text (the feature id when there is none); a polygon
    gives the exterior ring of its first part.
    """
    same = not crs.isValid() or layer.crs() == crs
    ct = None if same else QgsCoordinateTransform(layer.crs(), crs, project)
    id_field = layer.fields().indexFromName("id")
    names = [n.lower() for n in layer.fields().names()]
    polygon = layer.geometryType() == _POLYGON
    features, fids = [], []
    for f in layer.getFeatures():
        g = QgsGeometry(f.geometry())
        if g.isEmpty():
            continue
        if ct is not None:
            g.transform(ct)
        if polygon:
            parts = g.asGeometryCollection() if g.isMultipart() else [g]
            g = QgsGeometry(parts[0].constGet().exteriorRing().clone())
        values = f.attributes()
        attrs = {n: _plain(v) for n, v in zip(names, values)}
        fid = str(f.id()) if id_field < 0 else str(values[id_field])
        features.append(ControlFeature(fid, _vertices(g), attrs, same))
        fids.append(f.id())
    return features, fids


def read_tables(planes: str, lines: str, lcps: str) -> tuple[list | None, ...]:
    """The plane, line and LCP tables ("" or None: not given -> None).

    Raises
    ------
    InputError, OSError
        A table that cannot be read (the message names the file, row and column).
    """
    return (
        read_planes_csv(planes) if planes else None,
        read_lines_csv(lines) if lines else None,
        read_lcps_csv(lcps) if lcps else None,
    )


class ControlLinks:
    """Which layer feature each target id of the control came from (map selection)."""

    def __init__(self) -> None:
        self.layers: dict[str, object] = dict.fromkeys(KINDS)
        self.fids: dict[str, dict[str, int]] = {k: {} for k in KINDS}

    def select(self, kind: str, target_id: str) -> None:
        """Select the feature of a target on the map (nothing when it has none)."""
        layer, fid = self.layers[kind], self.fids[kind].get(target_id)
        if layer is not None and fid is not None:
            layer.selectByIds([fid])

    def selected(self, kind: str) -> set[str]:
        """Target ids whose features are selected on the map."""
        layer = self.layers[kind]
        if layer is None:
            return set()
        sel = set(layer.selectedFeatureIds())
        return {t for t, fid in self.fids[kind].items() if fid in sel}


def read_control(layers: dict, tables: tuple, crs, project) -> tuple[ControlSet, ControlLinks]:
    """The control of the three layers (``{kind: layer or None}``) with the tables' rows."""
    links = ControlLinks()
    feats = {}
    for kind in KINDS:
        layer = layers.get(kind)
        links.layers[kind] = layer
        feats[kind], fids = layer_features(layer, crs, project) if layer is not None else ([], [])
        links.fids[kind] = {f.id: fid for f, fid in zip(feats[kind], fids)}
    control = ControlSet.from_features(feats["planes"], feats["lines"], feats["lcps"])
    return control.with_tables(*tables), links
