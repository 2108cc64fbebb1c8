"""Agisoft Metashape camera XML (*Export Cameras > Agisoft XML*) -> the project's cameras and EO.

The file
--------
``document/chunk`` (or a ``chunk`` root, as in a project's ``chunk.zip``) holds ``sensors``
(one ``sensor`` per camera model: ``type`` frame or fisheye, its ``resolution`` and
``calibration`` elements, the ``adjusted`` one taken first, with ``f cx cy k1..k4 p1 p2 b1
b2`` in pixels / unitless), ``components`` (Metashape 2: one ``transform`` per component and
a ``partition`` of camera ids), ``cameras`` (``camera`` elements, possibly inside ``group``
elements, with ``sensor_id``, ``component_id``, ``label`` and a ``transform``: 16 numbers,
the 4 x 4 camera -> internal matrix, row by row), a chunk ``transform`` (``rotation`` 3 x 3
row by row, ``translation``, ``scale``: internal -> world, ``X = s R x + t``) and the
``reference`` (the chunk's CRS as WKT: world coordinates are geocentric (ECEF) for a
geographic or projected CRS, the local coordinates themselves for ``LOCAL_CS``).

A camera's internal frame is its component's (the component's ``transform`` maps it to the
world; in Metashape 2 the chunk's ``transform`` is the active component's), else the chunk's.
A camera with no ``transform`` (not aligned), whose sensor is missing or has no
calibration, or whose component has no transform in a georeferenced chunk is skipped and
reported by label; so are the cameras of other components than the active one in a local
chunk (their frames differ).

Cameras (Metashape Professional manual, appendix "Camera models")
----------------------------------------------------------------
Camera frame x right, y down, z forward (the camera looks along +z); ``x = X/Z, y = Y/Z``
(fisheye: scaled to the length ``atan(r)``), ``x' = x (1 + k1 r^2 + .. + k4 r^8) + p1 (r^2 +
2 x^2) + 2 p2 x y``, ``y' = y (..) + p2 (r^2 + 2 y^2) + 2 p1 x y``, ``u = w/2 + cx + x' (f +
b1) + y' b2``, ``v = h/2 + cy + y' f`` with ``(u, v)`` from the image's top-left corner (the
image centre at ``w/2, h/2``: the project's pixel convention). That is
:class:`~core.geometry.forward_lens.MetashapeLens` with Metashape's own coefficients
(``scale_mm = focal_mm = f * pixel size``, ``focal_px = f``), the ``perspective`` projection
for frame sensors and ``equidistant`` for fisheye ones, ``x0 = cx * ps``, ``y0 = -cy * ps``.
Nonzero ``p3``, ``p4`` (no model of ours holds them), other sensor types (spherical,
cylindrical, RPC) and PhotoScan's ``fx fy`` calibrations are refused by name. The pixel
size is the sensor's ``pixel_width`` property when given (else PIXEL_SIZE); it scales the
millimetres, never the projection.

Orientations
------------
``R_wc = R_world R_cam`` (camera -> world; the transform's scale does not rotate) and the
centre ``C = s R_world t_cam + t_world``; world -> camera ``R = R_wc^T`` and ``t = -R C``
give the project's orientation as COLMAP's do (:func:`core.io.colmap_block.oriented`:
``M = diag(1, -1, -1) R``), in ECEF turned to the grid frame at each centre.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Mapping, Tuple

import numpy as np
from numpy.typing import NDArray

from ..errors import CrsError, InputError
from ..geometry.camera import Camera
from ..geometry.forward_lens import MetashapeLens
from ..geometry.rotations import nearest_rotation
from ..photo.bundle_setup import DEFAULT_CONTROL_SIGMA_M, GroundPoints
from ..photo.observations import DEFAULT_SIGMA_PX, ImageObservations
from .colmap_block import ColmapBlock, ColmapFrame, oriented
from .colmap_names import METASHAPE_IMAGE_NAMES

Array = NDArray[np.float64]
log = logging.getLogger(__name__)

__all__ = [
    "IMAGE_NAMES",
    "MarkerProjection",
    "MetashapeCamera",
    "MetashapeChunk",
    "MetashapeMarker",
    "MetashapeSensor",
    "Similarity",
    "block_from_metashape",
    "camera_from_metashape",
    "marker_tables",
    "read_metashape",
]

#: The EO's image names: the camera labels, or their file names (see colmap_names).
IMAGE_NAMES = METASHAPE_IMAGE_NAMES
#: Calibration coefficients read (absent ones are 0).
COEFFICIENTS = ("k1", "k2", "k3", "k4", "p1", "p2", "b1", "b2")
_SENSOR_TYPES = {"frame": "perspective", "fisheye": "equidistant"}
#: Rotation matrices are orthonormalised when within this of a rotation (the files' digits).
_ROTATION_TOL = 1e-5


@dataclass(frozen=True)
class Similarity:
    """``X = scale * rotation @ x + translation`` (internal -> world; metres, unitless)."""

    rotation: Array
    translation: Array
    scale: float = 1.0

    def apply(self, x: Array) -> Array:
        """(N, 3) internal -> (N, 3) world."""
        return self.scale * x @ self.rotation.T + self.translation


@dataclass(frozen=True)
class MetashapeSensor:
    """One sensor: id, label, type (frame, fisheye), size (px), calibration (f, cx, cy px and
    :data:`COEFFICIENTS`), pixel size (mm, 0 when the file has none); ``calibration`` is None
    for a sensor without one (its cameras are skipped)."""

    sensor_id: str
    label: str
    kind: str
    width: int
    height: int
    calibration: Mapping[str, float] | None
    pixel_size_mm: float = 0.0


@dataclass(frozen=True)
class MetashapeCamera:
    """One aligned camera: label, sensor id, component id ("" for none) and its 4 x 4
    camera -> internal transform (the camera frame x right, y down, z forward)."""

    camera_id: str
    label: str
    sensor_id: str
    component_id: str
    transform: Array


@dataclass(frozen=True)
class MetashapeMarker:
    """One marker: id, label, its reference (x, y, z in the marker CRS; None without one),
    whether the reference is enabled (control) or not (check), its sigmas (m; None: the
    chunk's marker accuracy)."""

    marker_id: str
    label: str
    xyz: Tuple[float, float, float] | None
    enabled: bool
    sigma: Tuple[float, float, float] | None


@dataclass(frozen=True)
class MarkerProjection:
    """A marker's location on a camera: pixels (u, v) from the image's top-left corner;
    ``pinned`` for a location placed by the user (Metashape's green flag)."""

    marker_id: str
    camera_id: str
    uv: Tuple[float, float]
    pinned: bool


@dataclass(frozen=True)
class MetashapeChunk:
    """A chunk of a camera XML: sensors, aligned cameras, component and chunk transforms,
    the reference CRS (WKT, "" for none), the active component and the skipped cameras
    (label, reason); its markers, their locations on the cameras, their CRS (WKT, "" for
    the chunk's) and the chunk's marker accuracy (m)."""

    sensors: Dict[str, MetashapeSensor]
    cameras: Tuple[MetashapeCamera, ...]
    components: Dict[str, Similarity | None]
    chunk_transform: Similarity | None
    reference_wkt: str
    active_component: str
    skipped: Tuple[Tuple[str, str], ...]
    source: str
    markers: Tuple[MetashapeMarker, ...] = ()
    projections: Tuple[MarkerProjection, ...] = ()
    marker_reference_wkt: str = ""
    marker_sigma_m: float = DEFAULT_CONTROL_SIGMA_M


# ---------------------------------------------------------------------- reading
def _attr(el: ET.Element, key: str, what: str, src: str) -> float | None:
    val = el.get(key)
    if val is None:
        return None
    try:
        out = float(val)
    except ValueError:
        out = float("nan")
    if not np.isfinite(out):
        raise InputError(f"{what}: attribute {key} is not a finite number: {val!r}", path=src)
    return out


def _numbers(el: ET.Element | None, n: int, what: str, src: str) -> Array:
    text = (el.text or "") if el is not None else ""
    try:
        vals = np.array([float(v) for v in text.split()], dtype=np.float64)
    except ValueError:
        vals = np.zeros(0)
    if vals.shape != (n,) or not np.all(np.isfinite(vals)):
        raise InputError(f"{what}: expected {n} numbers, got {text.strip()[:60]!r}", path=src)
    return vals


def _rotation(m: Array, what: str, src: str) -> Array:
    """The rotation nearest ``m`` (3, 3), refused unless within :data:`_ROTATION_TOL`."""
    try:
        return nearest_rotation(m, _ROTATION_TOL)
    except ValueError as exc:
        raise InputError(f"{what}: not a rotation matrix ({exc})", path=src) from None


def _similarity(el: ET.Element | None, what: str, src: str) -> Similarity | None:
    if el is None:
        return None
    rot = el.find("rotation")
    r = (
        np.eye(3)
        if rot is None
        else _rotation(
            _numbers(rot, 9, f"{what} rotation", src).reshape(3, 3), f"{what} rotation", src
        )
    )
    tr = el.find("translation")
    t = np.zeros(3) if tr is None else _numbers(tr, 3, f"{what} translation", src)
    sc = el.find("scale")
    s = 1.0 if sc is None else float(_numbers(sc, 1, f"{what} scale", src)[0])
    if not s > 0:
        raise InputError(f"{what} scale must be positive, got {s}", path=src)
    return Similarity(r, t, s)


def _calibration(sensor: ET.Element, what: str, src: str) -> Dict[str, float] | None:
    cals = sensor.findall("calibration")
    if not cals:
        return None
    cal = next((c for c in cals if c.get("class") == "adjusted"), cals[0])
    if cal.find("f") is None:
        if cal.find("fx") is not None:
            raise InputError(
                f"{what}: a PhotoScan calibration (fx, fy) is not supported; "
                "export the cameras again from Metashape 1.4 or later",
                path=src,
            )
        raise InputError(f"{what}: the calibration has no focal length <f>", path=src)
    out: Dict[str, float] = {}
    for key in ("f", "cx", "cy", *COEFFICIENTS, "p3", "p4"):
        el = cal.find(key)
        out[key] = 0.0 if el is None else float(_numbers(el, 1, f"{what} {key}", src)[0])
    for key in ("p3", "p4"):
        if out.pop(key) != 0.0:
            raise InputError(
                f"{what}: calibration coefficient {key} is not supported (no lens "
                "model of the project holds Metashape's p3, p4)",
                path=src,
            )
    if not out["f"] > 0:
        raise InputError(f"{what}: the focal length f must be positive, got {out['f']}", path=src)
    res = cal.find("resolution")
    if res is not None:
        out["width"] = _attr(res, "width", f"{what} calibration resolution", src) or 0.0
        out["height"] = _attr(res, "height", f"{what} calibration resolution", src) or 0.0
    return out


def _read_sensor(el: ET.Element, src: str) -> MetashapeSensor:
    sid = el.get("id", "")
    what = f"sensor {sid} ({el.get('label', '')})"
    kind = el.get("type", "frame")
    cal = _calibration(el, what, src)
    if kind not in _SENSOR_TYPES:
        raise InputError(
            f"{what}: Metashape sensor type '{kind}' is not supported (frame and fisheye are)",
            path=src,
        )
    res = el.find("resolution")
    w = (_attr(res, "width", what, src) or 0.0) if res is not None else 0.0
    h = (_attr(res, "height", what, src) or 0.0) if res is not None else 0.0
    if cal is not None and "width" in cal:
        w, h = cal.pop("width"), cal.pop("height")
    if not (w >= 1 and h >= 1 and w == int(w) and h == int(h)):
        raise InputError(f"{what}: the resolution must be positive integers", path=src)
    ps = 0.0
    for prop in el.findall("property"):
        if prop.get("name") == "pixel_width":
            ps = _attr(prop, "value", f"{what} pixel_width", src) or 0.0
    return MetashapeSensor(
        sid,
        el.get("label", ""),
        kind,
        int(w),
        int(h),
        cal,
        ps if np.isfinite(ps) and ps > 0 else 0.0,
    )


def _chunk_of(root: ET.Element, src: str) -> ET.Element:
    if root.tag == "chunk":
        return root
    chunks = root.findall("chunk")
    if root.tag != "document" or not chunks:
        raise InputError("not a Metashape camera file (expected <document><chunk>)", path=src)
    if len(chunks) > 1:
        log.warning("%s: %d chunks, the first is read", src, len(chunks))
    return chunks[0]


def _triple(
    el: ET.Element, keys: Tuple[str, str, str], what: str, src: str
) -> Tuple[float, float, float] | None:
    """Three numeric attributes, or None when any is absent."""
    a, b, c = (_attr(el, k, what, src) for k in keys)
    return (a, b, c) if a is not None and b is not None and c is not None else None


def _read_markers(
    chunk: ET.Element, src: str
) -> Tuple[Tuple[MetashapeMarker, ...], Tuple[MarkerProjection, ...], float]:
    """The chunk's markers (``markers/marker`` with their ``reference``), their locations
    (``frames/frame/markers/marker/location``) and the marker accuracy of its settings."""
    markers = []
    for el in chunk.iterfind("markers//marker"):
        mid = el.get("id", "")
        what = f"marker {el.get('label', mid)!r}"
        ref = el.find("reference")
        xyz: Tuple[float, float, float] | None = None
        sig: Tuple[float, float, float] | None = None
        enabled = False
        if ref is not None:
            xyz = _triple(ref, ("x", "y", "z"), what, src)
            enabled = ref.get("enabled", "false").lower() in ("true", "1")
            sig = _triple(ref, ("sx", "sy", "sz"), what, src)
            sxyz = _attr(ref, "sxyz", what, src)
            if sig is None and sxyz is not None:
                sig = (sxyz, sxyz, sxyz)
            if sig is not None and not min(sig) > 0:
                raise InputError(f"{what}: its reference accuracy must be positive", path=src)
        markers.append(MetashapeMarker(mid, el.get("label", mid), xyz, enabled, sig))
    projections = []
    for mk in chunk.iterfind("frames/frame/markers/marker"):
        mid = mk.get("marker_id", "")
        for loc in mk.iterfind("location"):
            what = f"marker {mid} on camera {loc.get('camera_id', '')}"
            u, v = _attr(loc, "x", what, src), _attr(loc, "y", what, src)
            if u is None or v is None:
                raise InputError(f"{what}: the location needs x and y", path=src)
            pinned = loc.get("pinned", "true").lower() in ("true", "1")
            projections.append(MarkerProjection(mid, loc.get("camera_id", ""), (u, v), pinned))
    sigma = DEFAULT_CONTROL_SIGMA_M
    for prop in chunk.iterfind("settings/property"):
        if prop.get("name") == "accuracy_markers":
            val = _attr(prop, "value", "settings accuracy_markers", src)
            sigma = val if val is not None and val > 0 else sigma
    return tuple(markers), tuple(projections), sigma


def read_metashape(path: str | Path) -> MetashapeChunk:
    """Read a Metashape camera XML (see the module docstring).

    Raises
    ------
    InputError
        Naming the file and the sensor, camera or element at fault.
    """
    src = str(path)
    try:
        root = ET.parse(src).getroot()
    except OSError as exc:
        raise InputError(f"cannot read the camera file: {exc.strerror or exc}", path=src) from exc
    except ET.ParseError as exc:
        raise InputError(f"not an XML file: {exc}", path=src) from exc
    chunk = _chunk_of(root, src)
    sensors_el = chunk.find("sensors")
    sensors = {
        s.sensor_id: s
        for s in (
            _read_sensor(e, src)
            for e in (sensors_el.findall("sensor") if sensors_el is not None else [])
        )
    }
    components: Dict[str, Similarity | None] = {}
    member: Dict[str, str] = {}
    comps = chunk.find("components")
    active = comps.get("active_id", "") if comps is not None else ""
    for comp in comps.findall("component") if comps is not None else []:
        cid = comp.get("id", "")
        components[cid] = _similarity(comp.find("transform"), f"component {cid} transform", src)
        for cam_id in (comp.findtext("partition/camera_ids") or "").split():
            member[cam_id] = cid
    cams_el = chunk.find("cameras")
    cameras: List[MetashapeCamera] = []
    skipped: List[Tuple[str, str]] = []
    labels: Dict[str, str] = {}
    for el in cams_el.iter("camera") if cams_el is not None else []:
        cam_id, label = el.get("id", ""), el.get("label", el.get("id", ""))
        sid = el.get("sensor_id", "")
        tr = el.find("transform")
        if tr is None or not (tr.text or "").strip():
            skipped.append((label, "not aligned (no transform)"))
            continue
        if sid not in sensors:
            skipped.append((label, f"sensor {sid!r} is not in the file"))
            continue
        if sensors[sid].calibration is None:
            skipped.append((label, f"sensor {sid!r} has no calibration"))
            continue
        if label in labels:
            raise InputError(
                f"cameras {labels[label]} and {cam_id} have the same label {label!r}", path=src
            )
        labels[label] = cam_id
        m = _numbers(tr, 16, f"camera {label!r} transform", src).reshape(4, 4)
        if not np.allclose(m[3], [0, 0, 0, 1]):
            raise InputError(f"camera {label!r} transform: the last row must be 0 0 0 1", path=src)
        m[:3, :3] = _rotation(m[:3, :3], f"camera {label!r} transform", src)
        comp_id = el.get("component_id", member.get(cam_id, ""))
        cameras.append(MetashapeCamera(cam_id, label, sid, comp_id, m))
    chunk_tr = _similarity(chunk.find("transform"), "chunk transform", src)
    ref = (chunk.findtext("reference") or "").strip()
    markers, projections, sigma = _read_markers(chunk, src)
    return MetashapeChunk(
        sensors,
        tuple(cameras),
        components,
        chunk_tr,
        ref,
        active,
        tuple(skipped),
        src,
        markers,
        projections,
        (chunk.findtext("marker_reference") or "").strip(),
        sigma,
    )


# ---------------------------------------------------------------------- conversion
def camera_from_metashape(sensor: MetashapeSensor, pixel_size_mm: float, name: str) -> Camera:
    """The project's camera of a calibrated Metashape sensor (exact; see the module docstring).
    ``pixel_size_mm`` is used when the sensor states none."""
    cal = dict(sensor.calibration or {})
    ps = sensor.pixel_size_mm or float(pixel_size_mm)
    f_px = cal["f"]
    f_mm = f_px * ps
    lens = MetashapeLens(
        **{k: cal[k] for k in COEFFICIENTS}, scale_mm=f_mm, aspect=1.0, focal_px=f_px
    )
    return Camera(
        name,
        f_mm,
        ps,
        sensor.width,
        sensor.height,
        cal["cx"] * ps,
        -cal["cy"] * ps,
        lens,
        _SENSOR_TYPES[sensor.kind],
    )


def chunk_frame(reference_wkt: str, crs: str) -> Tuple[ColmapFrame, bool]:
    """The frame of the chunk's world coordinates and whether they are geocentric: LOCAL for
    ``LOCAL_CS`` (or no reference), else ECEF converted into ``crs`` (default: the chunk's
    CRS when it is projected).

    Raises
    ------
    CrsError
        A geographic chunk without a projected ``crs``, or a ``crs`` for a local chunk.
    """
    ref = reference_wkt.strip()
    if not ref or ref.upper().startswith("LOCAL_CS"):
        if crs.strip():
            raise CrsError(
                "CRS: the chunk is in local coordinates (LOCAL_CS), which no CRS "
                "describes; leave CRS empty"
            )
        return ColmapFrame("local"), False
    from pyproj import CRS

    try:
        chunk_crs = CRS.from_wkt(ref)
    except Exception as exc:
        raise CrsError(f"the chunk's reference is not a CRS pyproj reads: {exc}") from exc
    target = crs.strip()
    if not target:
        horizontal = chunk_crs.sub_crs_list[0] if chunk_crs.is_compound else chunk_crs
        if not horizontal.is_projected:
            raise CrsError(
                f"CRS: the chunk is in {chunk_crs.name} ({horizontal.type_name}); "
                "give the projected CRS to convert it to (e.g. its UTM zone)"
            )
        target = chunk_crs.to_wkt()
    return ColmapFrame("ecef", target), True


def _world(
    chunk: MetashapeChunk, cam: MetashapeCamera, geocentric: bool
) -> Tuple[Similarity | None, str]:
    """The internal -> world similarity of a camera, or None and the reason it is skipped."""
    sim = chunk.components.get(cam.component_id)
    if sim is None and cam.component_id in ("", chunk.active_component):
        sim = chunk.chunk_transform  # Metashape 1: the chunk's; 2: the active component's
    if not geocentric:
        several = len({c.component_id for c in chunk.cameras}) > 1
        active = chunk.active_component or (chunk.cameras[0].component_id if chunk.cameras else "")
        if several and cam.component_id != active:
            return None, (
                f"component {cam.component_id} is not the active one ({active}): a "
                "local chunk's components have no common frame"
            )
        return sim or Similarity(np.eye(3), np.zeros(3)), ""
    if sim is None:
        return None, f"component {cam.component_id or '-'} has no transform (not georeferenced)"
    return sim, ""


def marker_tables(
    chunk: MetashapeChunk, imported: Mapping[str, str], frame: ColmapFrame
) -> Tuple[ImageObservations, GroundPoints]:
    """The markers as the observation table and ground points.

    Observations: the pinned locations (Metashape's green flags; its automatic, unpinned
    projections are left out) on the imported cameras (``imported``: camera id -> label),
    type ``control`` for a marker with reference coordinates, ``tie`` without (point_id =
    the marker's label), sigma 0.5 px. Ground points: the markers with reference
    coordinates, role ``control`` when the reference is enabled, else ``check``, their
    sigmas (else the chunk's marker accuracy), converted from the marker CRS (else the
    chunk's) into the frame's CRS (LOCAL: as they are).
    """
    by_id = {m.marker_id: m for m in chunk.markers}
    known = [m for m in chunk.markers if m.xyz is not None]
    xyz = np.array([m.xyz for m in known], dtype=np.float64).reshape(-1, 3)
    if known and frame.kind != "local":
        from pyproj import CRS

        from ..geometry.frames import parse_crs, transformer_3d

        wkt = chunk.marker_reference_wkt or chunk.reference_wkt
        try:
            src = CRS.from_wkt(wkt)
        except Exception as exc:
            raise CrsError(f"the markers' reference is not a CRS pyproj reads: {exc}") from exc
        tr = transformer_3d(src, parse_crs(frame.crs, what="CRS"))
        xyz = np.column_stack(tr.transform(xyz[:, 0], xyz[:, 1], xyz[:, 2]))
    sigma = np.array([m.sigma or (chunk.marker_sigma_m,) * 3 for m in known]).reshape(-1, 3)
    ground = GroundPoints(
        tuple(m.label for m in known),
        xyz,
        sigma,
        tuple("control" if m.enabled else "check" for m in known),
    )
    sel = [
        p
        for p in chunk.projections
        if p.pinned and p.camera_id in imported and p.marker_id in by_id
    ]
    n = len(sel)
    obs = ImageObservations(
        tuple(imported[p.camera_id] for p in sel),
        tuple(by_id[p.marker_id].label for p in sel),
        np.array([p.uv for p in sel], dtype=np.float64).reshape(-1, 2),
        np.full(n, DEFAULT_SIGMA_PX),
        tuple("control" if by_id[p.marker_id].xyz is not None else "tie" for p in sel),
        ("",) * n,
    )
    return obs, ground


def _image_name(label: str, image_names: str) -> str:
    """The image_id of a camera label (``file``: its file name without folder and extension;
    Metashape's labels may carry either separator)."""
    if image_names == "label":
        return label
    return Path(label.replace("\\", "/").rsplit("/", 1)[-1]).stem


def block_from_metashape(
    chunk: MetashapeChunk, crs: str, pixel_size_mm: float, image_names: str = IMAGE_NAMES[0]
) -> Tuple[ColmapBlock, Tuple[Tuple[str, str], ...]]:
    """Convert a chunk (see the module docstring): LOCAL or into ``crs``; returns the block
    (cameras ``metashape_<sensor id>``, one EO row per imported camera, image_id its label or,
    ``image_names`` ``file``, the label's file name without folder and extension; the
    markers as observations and ground points, :func:`marker_tables`) and every skipped
    camera (label, reason).

    Raises
    ------
    InputError
        No camera to import, an unknown ``image_names``, or two cameras of one image name.
    """
    if image_names not in IMAGE_NAMES:
        raise InputError(
            f"IMAGE_NAMES: expected one of {', '.join(IMAGE_NAMES)}, got {image_names!r}"
        )
    frame, geocentric = chunk_frame(chunk.reference_wkt, crs)
    skipped = list(chunk.skipped)
    rows: List[Tuple[MetashapeCamera, Array, Array]] = []
    for cam in chunk.cameras:
        sim, why = _world(chunk, cam, geocentric)
        if sim is None:
            skipped.append((cam.label, why))
            continue
        r_wc = sim.rotation @ cam.transform[:3, :3]
        centre = sim.apply(cam.transform[:3, 3].reshape(1, 3))[0]
        rows.append((cam, r_wc.T, -r_wc.T @ centre))
    for label, why in skipped:
        log.warning("camera %r skipped: %s", label, why)
    if not rows:
        raise InputError(
            "no camera to import (every camera was skipped: "
            f"{'; '.join(f'{lab}: {why}' for lab, why in skipped[:5])})",
            path=chunk.source,
        )
    rows.sort(key=lambda row: row[0].label)
    used = sorted({row[0].sensor_id for row in rows})
    names = {s: f"metashape_{s}" for s in used}
    cams = tuple(camera_from_metashape(chunk.sensors[s], pixel_size_mm, names[s]) for s in used)
    r = np.array([row[1] for row in rows])
    t = np.array([row[2] for row in rows])
    image_id = {row[0].camera_id: _image_name(row[0].label, image_names) for row in rows}
    first: Dict[str, str] = {}
    for row in rows:
        name = image_id[row[0].camera_id]
        if first.setdefault(name, row[0].label) != row[0].label:
            raise InputError(
                f"cameras {first[name]!r} and {row[0].label!r} are both image "
                f"{name!r}: use IMAGE_NAMES label",
                path=chunk.source,
            )
    eo, _ = oriented(frame, [image_id[row[0].camera_id] for row in rows], r, t, np.zeros((0, 3)))
    imported = image_id
    obs, ground = marker_tables(chunk, imported, frame)
    block = ColmapBlock(cams, eo, tuple(names[row[0].sensor_id] for row in rows), obs, ground)
    return block, tuple(skipped)
