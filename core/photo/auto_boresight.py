"""Automatic (click-free) boresight calibration from LiDAR roof lines and planes (issue 32).

From the images, the camera, the trajectory (INS/GNSS), the mount with an approximate
boresight and the LiDAR roof planes and lines (mapping CRS), without any hand-picked point:

1. Observability: a scene with no roof plane sloping more than ``min_slope_deg`` and fewer
   than ``min_line_directions`` distinct LiDAR line directions (flat ground, flat roofs) is
   refused with that reason (:class:`SceneNotObservable`): the angles are not observable.
2. Angle search (coarse to fine): the LiDAR lines, sampled in 3D, are projected into every
   image for boresight candidates on a grid of ``coarse_step_px`` (in the image; widened to
   an eighth of the range when larger) over +-``search_deg`` about the initial boresight
   (omega and phi together, then kappa), and the candidate whose projections lie on the
   strongest image edges (the sum of the gradient magnitude of the image blurred by about
   half a step) wins; the grid is then halved around
   it down to ``fine_step_px``. This is what lets a 1-degree initial error converge: the
   edge refinement of step 3 only looks a few pixels across a line.
3. Rounds: with the exterior orientation of the current estimate, line observations are
   found along the projected lines (:func:`.auto_lines.line_observations_block`, searched
   within 3 sigma of the projection's uncertainty, the pose's and the boresight's; an image's
   segment of a line off the displacement of the image's other segments is on another edge
   and is dropped before the adjustment, so data snooping, which rejects a LiDAR line's
   points in all images together, does not lose the good ones with it), tie
   tracks (optional input) are associated with roof planes within a gate of 3 sigma
   (:func:`.auto_ties.associate_ties`), and :func:`.boresight.calibrate` (robust stage and
   data snooping) adjusts them. The next round starts from the adjusted orientation; the
   rounds stop when every boresight angle changed by less than its standard deviation and
   the line points' variance components settled (after at least two rounds) or after
   ``max_rounds``.
4. Weighting of the line points: the points of one line in one image (a segment) share an
   error (the edge against the LiDAR line as seen from that image) that the sigma of the
   segment's own straight fit cannot carry. Each segment gets an offset and a tilt across
   the line as nuisance unknowns with priors (``BoresightOptions.line_segment_sigmas_px``;
   ``segment_sigma_px`` in the first round), and after each round the three variance
   components (the points' sigma scale, the offsets' and the tilts' sigma) are re-estimated
   from the residuals (:mod:`.boresight_weights`) for the next. Data snooping then tests a
   line's group at its significance per group (Bonferroni over its rows): a line of
   hundreds of points is not set aside for the largest of hundreds of normal residuals.

Angles are radians inside, pixel quantities (col, row) per docs/conventions.md.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.planes import Plane
from ..geometry.projection import ideal_from_camera
from ..geometry.rotations import boresight_matrix
from ..geometry.surface import Dsm
from ..lidar.control import ControlLine
from .auto_boresight_options import AutoBoresightOptions
from .auto_lines import REFUSALS, _grey, line_observations_block
from .auto_ties import REASONS, associate_ties
from .boresight import calibrate
from .boresight_options import BoresightOptions
from .boresight_result import BoresightResult
from .boresight_weights import line_variances
from .georeference import Trajectory, direct_georeference
from .ins import ins_grade
from .mount import Mount
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_map_to_local

__all__ = [
    "AutoBoresightOptions",
    "AutoBoresightResult",
    "RoundRecord",
    "SceneNotObservable",
    "auto_calibrate",
    "scene_refusal",
    "search_boresight",
]

Array = NDArray[np.float64]
#: the rounds stop when the line points' variance components also changed by less than this
#: factor (and the boresight by less than its sigma)
WEIGHTS_SETTLED = 1.25
Images = Sequence[tuple[str, ArrayLike]]


class SceneNotObservable(InputError):
    """The LiDAR scene cannot determine the boresight angles (the message says why)."""


@dataclass(frozen=True)
class RoundRecord:
    """One association-adjustment round: the search width (px) and tie gate (m) used, the
    observation counts, the boresight after it (G, 3, radians), its sigmas and its change, the
    points rejected by data snooping and the edge points refused before the adjustment per
    reason (:data:`.auto_lines.REFUSALS`)."""

    round: int
    search_px: float
    gate_m: float
    line_points: int
    lines_seen: int
    tie_tracks: int
    ties_associated: int
    ties_refused: dict[str, int]
    boresight: Array
    std: Array
    change: Array
    rejected: int
    lines_refused: dict[str, int] = field(default_factory=dict)
    #: the line points' weighting of the round (:class:`.boresight_weights.LineVariances`: the
    #: factor on their sigma_px, the segments' offset and tilt sigmas) and the variances the
    #: round's residuals gave (the next round's); None without segment nuisances
    weights: tuple[float, float, float] | None = None
    estimated: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class AutoBoresightResult:
    """Result of :func:`auto_calibrate`: the last calibration, the boresight the angle search
    gave (3,) radians, the rounds, the observations of the last round, and the images'
    line-point counts and tie counts per plane of the last round."""

    result: BoresightResult
    searched: Array
    rounds: list[RoundRecord]
    observations: ImageObservations
    converged: bool
    per_image: dict[str, int]
    per_plane: dict[str, int]


# ------------------------------------------------------------------ observability
def _directions(lines: Sequence[ControlLine], min_length: float = 1.0) -> int:
    """Number of distinct plan directions (15 degrees apart) among the lines."""
    az = sorted(
        float(np.degrees(np.arctan2(ln.direction[1], ln.direction[0]))) % 180.0
        for ln in lines
        if ln.length >= min_length and np.hypot(*ln.direction[:2]) > 0.2
    )
    count, last = 0, -1e9
    for a in az:
        if a - last >= 15.0:
            count, last = count + 1, a
    if count > 1 and az[0] + 180.0 - last < 15.0:  # the first and last wrap round
        count -= 1
    return count


def scene_refusal(
    planes: Sequence[Plane],
    lines: Sequence[ControlLine],
    options: AutoBoresightOptions | None = None,
) -> str:
    """Why the scene cannot determine the boresight ("" when it can; module docstring)."""
    opt = options or AutoBoresightOptions()
    sloped = [p for p in planes if opt.min_slope_deg <= p.slope_deg <= opt.max_roof_slope_deg]
    normals = np.array([p.normal for p in sloped]).reshape(-1, 3)
    distinct = normals.shape[0] > 1 and float(np.min(normals @ normals[0])) < np.cos(
        np.radians(10.0)
    )
    n_dir = _directions(lines)
    if distinct or n_dir >= opt.min_line_directions:
        return ""
    return (
        f"the LiDAR scene cannot determine the boresight angles: {len(sloped)} roof plane(s) "
        f"sloping {opt.min_slope_deg:g} to {opt.max_roof_slope_deg:g} degrees "
        f"({'one normal' if len(sloped) else 'none'}: flat ground or flat roofs only) and "
        f"{n_dir} LiDAR line direction(s) (at least {opt.min_line_directions} needed)"
    )


# ------------------------------------------------------------------ angle search
def _nominal_camera_vectors(
    traj: Trajectory,
    camera: Camera,
    mount: Mount,
    frame: MappingFrame,
    lines: Sequence[ControlLine],
    spacing_px: float,
) -> list[Array]:
    """Per image, LiDAR line samples (about ``spacing_px`` apart at the image scale) as vectors
    in the camera frame of a zero boresight: ``u = M0 (X - C)`` (local ENU, metres)."""
    zero = replace(mount, boresight=np.zeros(3))
    eo = direct_georeference(traj, zero, frame)
    local = LocalFrame.at_map_point(frame, eo.xyz.mean(axis=0))
    centres, m0 = eo_map_to_local(eo.xyz, eo.opk, local)
    pts = []
    for ln in lines:
        a, b = np.asarray(ln.start, float), np.asarray(ln.end, float)
        rng = float(np.min(np.abs(eo.xyz[:, 2] - (a[2] + b[2]) / 2)))
        gsd = max(rng, 1.0) / camera.focal_px
        n = int(np.clip(np.ceil(np.linalg.norm(b - a) / (gsd * spacing_px)), 2, 2000))
        t = (np.arange(n) + 0.5) / n
        pts.append(a + t[:, None] * (b - a))
    xyz = local.map_to_enu(np.vstack(pts)) if pts else np.empty((0, 3))
    return [(xyz - centres[i]) @ m0[i].T for i in range(len(traj))]


#: Most grid steps each side of the initial boresight at the search's first level.
_FIRST_STEPS = 8.0

#: Side of the tiles in which the edge strength is computed when the search first samples
#: them (reduced pixels): lines cover a small part of a large image.
_TILE = 64


class _EdgeStrength:
    """The gradient magnitude of one (reduced) grey image blurred by ``sigma`` pixels, computed
    tile by tile where it is sampled: each tile is filtered with a margin of the Gaussian's
    support (scipy's ``truncate`` of 4 sigma), or up to the image border, where the same
    reflection applies, so every value is the one the whole image's filter gives."""

    def __init__(self, grey: NDArray[np.float32], sigma: float) -> None:
        self.grey = grey
        self.sigma = float(sigma)
        self.pad = int(4.0 * self.sigma + 0.5) + 1
        # zeros are not touched until written: the memory follows the tiles computed
        self.values = np.zeros(grey.shape, dtype=np.float32)
        shape = (-(-grey.shape[0] // _TILE), -(-grey.shape[1] // _TILE))
        self.done = np.zeros(shape, dtype=bool)

    def sample(self, rows: Array, cols: Array) -> Array:
        """Bilinear samples at (rows, cols) in pixel-index coordinates (pixel centres at
        integers; ``scipy.ndimage.map_coordinates`` order 1: 0 outside the image)."""
        from scipy.ndimage import gaussian_gradient_magnitude, map_coordinates

        h, w = self.grey.shape
        r0 = np.floor(rows).astype(np.intp)
        c0 = np.floor(cols).astype(np.intp)
        # the tiles of the four neighbours of each sample
        ty = np.clip(np.concatenate([r0, r0, r0 + 1, r0 + 1]) // _TILE, 0, self.done.shape[0] - 1)
        tx = np.clip(np.concatenate([c0, c0 + 1, c0, c0 + 1]) // _TILE, 0, self.done.shape[1] - 1)
        need = np.zeros_like(self.done)
        need[ty, tx] = True
        for i, j in zip(*np.nonzero(need & ~self.done)):
            y0, x0 = i * _TILE, j * _TILE
            y1, x1 = min(h, y0 + _TILE), min(w, x0 + _TILE)
            a0, b0 = max(0, y0 - self.pad), max(0, x0 - self.pad)
            a1, b1 = min(h, y1 + self.pad), min(w, x1 + self.pad)
            g = gaussian_gradient_magnitude(self.grey[a0:a1, b0:b1], self.sigma)
            self.values[y0:y1, x0:x1] = g[y0 - a0 : y1 - a0, x0 - b0 : x1 - b0]
            self.done[i, j] = True
        return map_coordinates(self.values, [rows, cols], order=1)


class _Search:
    """The line samples of all images (stacked) and the images' edge strength at one blur."""

    def __init__(self, camera: Camera, us: list[Array], greys: list[NDArray[np.float32]]) -> None:
        self.camera = camera
        self.us = us
        self.greys = greys
        self.grads: list[_EdgeStrength] = []
        self.stride = 1
        self.reduce = 1
        self._blurred: tuple[float, int] = (-1.0, 0)

    def blur(
        self, sigma_px: float, stride: int, should_stop: Callable[[], bool] | None = None
    ) -> None:
        """Gradient magnitude of the images blurred by ``sigma_px`` (full-resolution pixels);
        every ``stride``-th sample. A wide blur is computed on the image reduced by an integer
        factor (box average) that keeps at least 2 reduced pixels of sigma: the search needs
        the edges' position at the blur's scale only, and a 24-Mpx image blurred by 30 px
        would otherwise cost seconds per candidate level. The blurred gradient is computed
        where the candidates sample it (:class:`_EdgeStrength`); ``should_stop`` is asked
        before each image (cancellation)."""
        import cv2

        r = max(1, int(sigma_px // 2.0))
        if self._blurred != (sigma_px, r):
            grads = []
            for full in self.greys:
                stop_if_asked(should_stop, "the boresight search (blurring the images)")
                g: NDArray = full
                if r > 1:
                    h, w = (g.shape[0] // r) * r, (g.shape[1] // r) * r
                    g = cv2.resize(g[:h, :w], (w // r, h // r), interpolation=cv2.INTER_AREA)
                grads.append(_EdgeStrength(g, sigma_px / r))
            self.grads, self.reduce, self._blurred = grads, r, (sigma_px, r)
        self.stride = max(1, int(stride))
        parts = [u[:: self.stride] for u in self.us]
        self.owner = np.repeat(np.arange(len(parts)), [len(p) for p in parts])
        self.u = np.vstack(parts) if parts else np.empty((0, 3))

    def score(self, bore: Array) -> float:
        """Mean edge strength under the projected lines (out-of-frame samples count 0)."""
        cam = self.camera
        q = self.u @ boresight_matrix(*bore)  # v = dR^T u, in rows
        ideal, valid = ideal_from_camera(q, cam.focal_mm, cam.projection)[:2]
        px, ok = cam.pixel_from_ideal_with_status(np.where(valid[:, None], ideal, 0.0))
        good = valid & ok & np.isfinite(px).all(axis=1)
        good[good] &= cam.in_frame(px[good], 2.0)
        total = 0.0
        for k, g in enumerate(self.grads):
            # reduced pixel j covers full-resolution [j r, (j + 1) r): its centre is at
            # (j + 1/2) r in the project's pixel convention (first pixel's centre at 0.5)
            p = px[good & (self.owner == k)] / self.reduce - 0.5
            if len(p):
                total += float(g.sample(p[:, 1], p[:, 0]).sum())
        return total / max(len(px), 1)

    def grid_best(
        self,
        centre: Array,
        steps: Array,
        half: int,
        axes: tuple[int, ...],
        tick: Callable[[], None] | None = None,
    ) -> Array:
        """The best candidate of a (2 half + 1)^len(axes) grid about ``centre``; ``tick`` is
        called before each candidate (:class:`_Ticker`: cancellation and progress)."""
        offsets = np.arange(-half, half + 1)
        grids = np.meshgrid(*[offsets * steps[a] for a in axes], indexing="ij")
        best, best_score = centre, -np.inf
        for combo in zip(*[g.ravel() for g in grids]):
            if tick is not None:
                tick()
            cand = centre.copy()
            for a, d in zip(axes, combo):
                cand[a] += d
            s = self.score(cand)
            if s > best_score:
                best, best_score = cand, s
        return best


class _Ticker:
    """Called before each candidate of the angle search: raises :class:`~..errors.Cancelled`
    when ``should_stop()`` says so (a cancel stops the search before the next candidate) and
    reports the fraction of the ``total`` candidates done to ``progress`` (0..1)."""

    def __init__(
        self,
        total: int,
        progress: Callable[[float], None] | None,
        should_stop: Callable[[], bool] | None,
    ) -> None:
        self.total, self.done = max(int(total), 1), 0
        self.progress, self.should_stop = progress, should_stop

    def __call__(self) -> None:
        stop_if_asked(self.should_stop, "the boresight search")
        if self.progress is not None and self.done % 8 == 0:
            self.progress(min(self.done / self.total, 1.0))
        self.done += 1


def search_boresight(
    traj: Trajectory,
    camera: Camera,
    mount: Mount,
    frame: MappingFrame,
    images: Images,
    lines: Sequence[ControlLine],
    options: AutoBoresightOptions | None = None,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[float], None] | None = None,
) -> Array:
    """Coarse-to-fine boresight (3,) radians whose projected LiDAR lines lie on the strongest
    image edges (module docstring, step 2). ``should_stop`` is asked before every candidate
    and every image's blur (cancellation); ``progress`` gets the fraction of candidates done."""
    opt = options or AutoBoresightOptions()
    if opt.search_deg == 0 or not lines:
        return np.asarray(mount.boresight, float).copy()
    spacing = max(opt.fine_step_px, 0.5)  # samples this far apart at the finest step
    us = _nominal_camera_vectors(traj, camera, mount, frame, lines, spacing)
    row = {iid: k for k, iid in enumerate(traj.image_id)}
    chosen, greys = [], []
    for iid, img in images:
        stop_if_asked(should_stop, "the boresight search")
        if iid not in row:
            raise InputError(f"image '{iid}' is not in the trajectory")
        chosen.append(us[row[iid]])
        greys.append(_grey(img).astype(np.float32))
    search = _Search(camera, chosen, greys)
    f = camera.focal_px
    half_diag = 0.5 * float(np.hypot(camera.width_px, camera.height_px))
    # the first grid spans the range in at most _FIRST_STEPS steps each side (and at least
    # coarse_step_px): the search costs the same number of candidates at any image size
    range_px = f * np.radians(opt.search_deg)
    step_px = max(float(opt.coarse_step_px), range_px / _FIRST_STEPS)
    levels = [step_px]  # the grid steps (px), halved down to fine_step_px
    while levels[-1] > opt.fine_step_px * 1.0001:
        levels.append(max(levels[-1] / 2.0, opt.fine_step_px))
    # the whole range at the first level: omega and phi together, then kappa
    n_op = int(np.ceil(np.radians(opt.search_deg) / (step_px / f)))
    n_k = int(np.ceil(np.radians(opt.search_deg) / (step_px / half_diag)))
    tick = _Ticker(
        (2 * n_op + 1) ** 2 + 2 * n_k + 1 + len(levels) * 2 * (25 + 5), progress, should_stop
    )
    bore = np.asarray(mount.boresight, float).copy()
    for level, step_px in enumerate(levels):
        stop_if_asked(should_stop, "the boresight search")
        search.blur(max(0.7, 0.6 * step_px), int(step_px / (2 * spacing)), should_stop)
        steps = np.array([step_px / f, step_px / f, step_px / half_diag])
        if level == 0:
            bore = search.grid_best(bore, steps, n_op, (0, 1), tick)
            bore = search.grid_best(bore, steps, n_k, (2,), tick)
        for _ in range(2):
            bore = search.grid_best(bore, steps, 2, (0, 1), tick)
            bore = search.grid_best(bore, steps, 2, (2,), tick)
    if progress is not None:
        progress(1.0)
    return bore


# ------------------------------------------------------------------ rounds
def _share(
    progress: Callable[[float], None] | None, lo: float, hi: float
) -> Callable[[float], None] | None:
    """``progress`` of one stage: its fraction 0..1 reported as ``lo``..``hi`` of the whole."""
    if progress is None:
        return None
    report = progress

    def stage(f: float) -> None:
        report(lo + (hi - lo) * min(max(float(f), 0.0), 1.0))

    return stage


def _checked(images: Images, should_stop, progress):
    """The images one at a time, ``should_stop`` asked before each (cancellation) and the
    fraction handed out reported to ``progress``."""
    for k, image in enumerate(images):
        stop_if_asked(should_stop, f"finding edges along the LiDAR lines (image {image[0]})")
        if progress is not None:
            progress(k / max(len(images), 1))
        yield image
    if progress is not None:
        progress(1.0)


def _counts(obs: ImageObservations, kind: str, key: str) -> dict[str, int]:
    out: dict[str, int] = {}
    for t, i, tid in zip(obs.type, obs.image_id, obs.target_id):
        if t == kind:
            k = i if key == "image" else tid
            out[k] = out.get(k, 0) + 1
    return out


def _round_observations(images, cam, eo, lines, ties, planes, dsm, opt, search_px, gate):
    """One round's observations: the line points found along the projected lines within
    ``search_px`` and the tie tracks associated with the planes within ``gate`` (m); returns
    (line observations, all observations, tie refusals per reason, tie tracks tried, line
    point refusals per reason)."""
    line_refused = dict.fromkeys(REFUSALS, 0)
    line_obs = line_observations_block(
        images, cam, eo, lines, replace(opt.lines, search_px=search_px), line_refused
    )
    if ties is None or not len(ties):
        return line_obs, line_obs, dict.fromkeys(REASONS, 0), 0, line_refused
    assoc = associate_ties(
        ties,
        eo,
        cam,
        planes,
        gate,
        border_m=opt.border_m,
        max_roof_slope_deg=opt.max_roof_slope_deg,
        dsm=dsm,
    )
    return (
        line_obs,
        line_obs.concat(assoc.observations),
        assoc.reasons,
        assoc.tracks,
        line_refused,
    )


def _settled(used, estimated, negligible: float) -> bool:
    """Whether the line points' variance components settled: each changed by less than the
    factor :data:`WEIGHTS_SETTLED`, or a segment sigma stayed below ``negligible`` px (the
    points' sigma floor: the iteration creeps towards zero there)."""
    for j, (a, b) in enumerate(zip(used, estimated)):
        if j and max(a, b) <= negligible:
            continue
        if abs(np.log(b / a)) >= np.log(WEIGHTS_SETTLED):
            return False
    return True


def _scaled(obs: ImageObservations, scale: float) -> ImageObservations:
    """``obs`` with the sigma_px of its line points multiplied by ``scale``."""
    if scale == 1.0:
        return obs
    line = np.array([t == "line" for t in obs.type], bool)
    return replace(obs, sigma_px=np.where(line, obs.sigma_px * scale, obs.sigma_px))


def _round_record(k, search_px, gate, line_obs, obs, n_tracks, refused, result, change, lines):
    """The :class:`RoundRecord` of round ``k`` (counts, the boresight, its change)."""
    tie_ids = {p for p, t in zip(obs.point_id, obs.type) if t == "tie"}
    return RoundRecord(
        k,
        search_px,
        gate,
        len(line_obs),
        len(set(line_obs.target_id)),
        n_tracks,
        len(tie_ids),
        refused,
        result.boresight.copy(),
        result.std.copy(),
        change,
        int(result.residuals.rejected.sum()),
        dict(lines),
    )


def auto_calibrate(
    trajectory: Trajectory,
    camera: Camera,
    mount: Mount,
    crs: Union[str, MappingFrame],
    images: Images,
    planes: Sequence[Plane] = (),
    lines: Sequence[ControlLine] = (),
    ties: ImageObservations | None = None,
    dsm: Dsm | None = None,
    options: AutoBoresightOptions | None = None,
    calibration: BoresightOptions | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> AutoBoresightResult:
    """Calibrate the boresight without hand picks (module docstring).

    Parameters
    ----------
    trajectory : Trajectory
        INS/GNSS poses of the images (the approximate EO with ``mount``).
    camera : Camera
    mount : Mount
        Lever arm, nominal mount and the approximate boresight (radians).
    crs : str or MappingFrame
        Mapping CRS of the trajectory, planes, lines and DSM.
    images : sequence of (image_id, array)
        Grey or RGB images of the camera's size (a list: it is read in every round).
    planes, lines : sequences
        LiDAR roof planes (with outlines for ties) and ridge/hip/valley lines.
    ties : ImageObservations, optional
        Tie tracks (rows of type ``tie``, e.g. from ``tiepoints``); associated with planes.
    dsm : Dsm, optional
        LiDAR DSM: ties off it are refused.
    options : AutoBoresightOptions, optional
    calibration : BoresightOptions, optional
        Options of the adjustment (``use_types`` is set to tie and line).
    progress, should_stop : callables, optional
        Fraction done (0..1); cancellation.

    Raises
    ------
    SceneNotObservable
        A flat scene (module docstring, step 1), or no observation found.
    """
    opt = options or AutoBoresightOptions()
    frame = crs if isinstance(crs, MappingFrame) else MappingFrame.from_user_input(crs)
    why = scene_refusal(planes, lines, opt)
    if why:
        raise SceneNotObservable(why)
    images = list(images)
    base = calibration or BoresightOptions()
    cal = replace(base, use_types=("tie", "line"), snooping_per_group=opt.segment_sigma_px > 0)
    grade = ins_grade(base.ins_grade) if isinstance(base.ins_grade, str) else base.ins_grade
    att_sigma = np.radians(max(grade.sigma_roll_pitch_deg, grade.sigma_heading_deg))
    searched = search_boresight(
        trajectory, camera, mount, frame, images, lines, opt, should_stop, _share(progress, 0, 0.3)
    )
    current = replace(mount, boresight=searched)
    eo: ExteriorOrientationTable = direct_georeference(trajectory, current, frame)
    bore_sigma = opt.fine_step_px / camera.focal_px if opt.search_deg > 0 else 0.0
    height = (
        float(np.median(eo.xyz[:, 2]) - np.median([p.centroid[2] for p in planes]))
        if planes
        else float(np.median(eo.xyz[:, 2]))
    )
    rounds: list[RoundRecord] = []
    cam = camera  # with the interior estimated, the last round's (and the lever arm's)
    last = np.asarray(searched, float)[None, :]
    result, obs, converged = None, None, False
    weights = (1.0, opt.segment_sigma_px, opt.segment_sigma_px)  # sigma scale, offset, tilt
    for r in range(int(opt.max_rounds)):
        stop_if_asked(should_stop, "the automatic calibration")
        spread = float(np.hypot(bore_sigma, att_sigma))
        search_px = max(opt.min_search_px, opt.sigmas * camera.focal_px * spread)
        gate = max(opt.min_gate_m, opt.sigmas * abs(height) * spread)
        lo, half = 0.3 + 0.7 * r / opt.max_rounds, 0.35 / opt.max_rounds  # this round's share
        line_obs, obs, refused, n_tracks, line_refused = _round_observations(
            _checked(images, should_stop, _share(progress, lo, lo + half)),
            *(cam, eo, lines, ties, planes, dsm, opt, search_px, gate),
        )
        if len(obs) == 0:
            raise SceneNotObservable(
                "no image edge was found along the projected LiDAR lines and no tie track lies "
                f"on a roof plane (round {r + 1}, search {search_px:.1f} px): the approximate "
                "boresight or the mount is too far off, or the lines are not in the images"
            )
        obs = _scaled(obs, weights[0])
        result = calibrate(
            trajectory,
            cam,
            current,
            frame,
            obs,
            planes,
            lines,
            options=replace(cal, line_segment_sigmas_px=weights[1:]),
            progress=_share(progress, lo + half, lo + 2 * half),
            should_stop=should_stop,
        )
        change = result.boresight - last
        used, estimated = weights, None
        if opt.segment_sigma_px > 0:
            v = line_variances(result, weights[1:])
            estimated = (weights[0] * v.scale, max(v.offset_px, 0.01), max(v.tilt_px, 0.01))
        record = _round_record(
            *(r + 1, search_px, gate, line_obs, obs, n_tracks, refused, result, change),
            line_refused,
        )
        rounds.append(replace(record, weights=used if estimated else None, estimated=estimated))
        if estimated:
            weights = estimated
        if progress:
            progress(0.3 + 0.7 * (r + 1) / opt.max_rounds)
        settled = estimated is None or _settled(used, estimated, opt.lines.min_sigma_px)
        if r >= 1 and settled and bool(np.all(np.abs(change) < result.std)):
            converged = True
            break
        last = result.boresight.copy()
        bore_sigma = float(np.max(result.std))
        eo = result.eo
        current = replace(mount, boresight=result.boresight.mean(axis=0))
        if result.lever_arm is not None:
            current = replace(current, lever_arm=np.asarray(result.lever_arm, float).copy())
        if result.interior is not None:
            f, x0, y0 = (float(a) for a in result.interior)
            cam = replace(cam, focal_mm=f, x0_mm=x0, y0_mm=y0)
    assert result is not None and obs is not None
    if progress:
        progress(1.0)
    return AutoBoresightResult(
        result,
        np.asarray(searched, float),
        rounds,
        obs,
        converged,
        _counts(obs, "line", "image"),
        _counts(obs, "tie", "plane"),
    )
