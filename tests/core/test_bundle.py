"""Bundle adjustment with self-calibration against simulated truth (the UAV block of Lima,
Debiasi & Menezes: Canon IXUS 120 IS, 15 images in 4 strips at 188 m, 70 %/60 % overlap,
16 control and 5 check points), and its refusals of tables that cannot make a block.

Tolerances follow from the noise put in: 0.5 px image noise, 1 / 1.5 cm survey noise, the
reported a-posteriori sigmas for recovered parameters (3 sigma), chi-square bounds for
Monte Carlo statistics.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import InputError, NotObservableError
from lidarphoto.core.geometry.ap_models import make_ap_model
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions, GroundPoints
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from scipy import stats

FAMILIES = ("none", "lens_k1k2", "bauer", "jacobsen", "ebner", "brown", "conrady_brown")
INSERTED = ("lens_k1k2", "bauer", "jacobsen", "ebner", "brown", "real")
PLAIN = {"robust": "none", "snooping": False, "ap_selection": False}
N_TIE = 500


def _run(blk, model, eo="dg", sigma=True, **kw):
    opts = BundleOptions(ap_model=model, **{**PLAIN, **kw})
    table = blk.eo_dg if eo == "dg" else eo
    return bundle_adjust(
        [blk.camera],
        blk.observations,
        blk.ground,
        blk.mapping,
        table,
        blk.eo_sigma if sigma else None,
        options=opts,
    )


def _truth(blk, name: str) -> float:
    io = {
        "focal_mm": blk.true_camera.focal_mm,
        "x0_mm": blk.true_camera.x0_mm,
        "y0_mm": blk.true_camera.y0_mm,
    }
    return io[name] if name in io else blk.true_ap[name]


@pytest.fixture(scope="module")
def blocks():
    return {m: simulate_uav_block(m, seed=1, n_tie=N_TIE) for m in INSERTED}


@pytest.mark.parametrize("inserted", INSERTED)
def test_inserted_family_is_recovered_within_three_sigma(blocks, inserted):
    blk = blocks[inserted]
    model = "conrady_brown" if inserted == "real" else inserted
    res = _run(blk, model)
    assert res.adjustment.converged
    r = res.adjustment.redundancy
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], r) / r
    assert lo < res.sigma0**2 < hi, res.sigma0
    est = [p for p in res.interior if p.status == "estimated"]
    assert len(est) == 3 + len(blk.true_ap)
    z = {p.name: (p.value - _truth(blk, p.name)) / p.std for p in est}
    assert all(abs(v) < 3.0 for v in z.values()), z
    # the check points agree with the survey within their combined sigmas
    st = res.check.statistics()
    assert st["n"] >= 4 and st["rms_3d"] < 0.2


def _representation_error_px(inserted_blk, family: str) -> float:
    """RMS (px) of what the family (with f, x0, y0 and the first-order effects of the
    orientation of a near-vertical image) cannot reproduce of the inserted correction field:
    a linear least-squares fit in image space, independent of the bundle adjustment."""
    cam = inserted_blk.true_camera
    w, h = cam.width_px * cam.pixel_size_mm, cam.height_px * cam.pixel_size_mm
    gx, gy = np.meshgrid(np.linspace(-w / 2, w / 2, 25), np.linspace(-h / 2, h / 2, 19))
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    target = cam.distortion.correction(xy).T.ravel()
    x, y, f = xy[:, 0], xy[:, 1], cam.focal_mm
    z, o = np.zeros_like(x), np.ones_like(x)
    cols = [
        np.r_[o, z],
        np.r_[z, o],
        np.r_[x, y],
        np.r_[-y, x],
        np.r_[f + x * x / f, x * y / f],
        np.r_[x * y / f, f + y * y / f],
    ]
    if family != "none":
        model = make_ap_model(family, w, h, cam.focal_mm)
        jp = model.jacobian_params(xy)
        cols += [jp[:, :, k].T.ravel() for k in range(model.n_params)]
    A = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(A, target, rcond=None)
    return float(np.sqrt(np.mean((A @ coef - target) ** 2)) / cam.pixel_size_mm)


@pytest.mark.parametrize("inserted", INSERTED)
def test_inserted_family_wins_the_check_point_ranking(blocks, inserted):
    """Every family adjusts the block; the inserted one (the physical model for the real
    lens) is at the top of the check-point ranking, tied only with families that can
    represent the same image deformation (independent image-space fit below 0.3 px), and
    every family that cannot (above 1.5 px) ranks below it."""
    blk = blocks[inserted]
    own = "conrady_brown" if inserted == "real" else inserted
    rms, rep = {}, {}
    for fam in FAMILIES:
        res = _run(blk, fam)
        rms[fam] = res.check.statistics()["rms_3d"]
        rep[fam] = _representation_error_px(blk, fam)
    assert rep[own] < 1e-6
    best = min(rms.values())
    ties = [f for f in FAMILIES if rep[f] < 0.3]
    assert rms[own] <= 1.25 * min(rms[f] for f in ties) + 0.005, (rms, rep)
    assert rms[own] <= 1.25 * best + 0.005, (rms, rep)
    for fam in FAMILIES:
        if rep[fam] > 1.5:
            assert rms[fam] > rms[own], (fam, rms, rep)


def test_monte_carlo_errors_match_the_reported_sigmas():
    """40 noise draws on one geometry (Ebner's 12 APs + f, x0, y0 + the 90 orientation
    parameters): the squared Mahalanobis distance of each draw's interior-orientation error
    under its reported covariance is chi-square with 15 degrees of freedom; the sum over the
    draws must fall inside the two-sided 0.1 % bounds of chi-square(600). The same for the
    orientation errors normalised by their sigmas (pooled)."""
    draws, d2, eo_z = 40, [], []
    for k in range(draws):
        blk = simulate_uav_block("ebner", seed=1, noise_seed=1000 + k, n_tie=300)
        res = _run(blk, "ebner")
        est = [p for p in res.interior if p.status == "estimated"]
        err = np.array([p.value - _truth(blk, p.name) for p in est])
        idx = np.array([res.adjustment.names.index(f"{p.camera} {p.name}") for p in est])
        cov = res.adjustment.covariance_of(idx, prior=True)
        d2.append(float(err @ np.linalg.solve(cov, err)))
        from lidarphoto.core.photo.orientation import eo_map_to_local

        c_est, _ = eo_map_to_local(res.eo.xyz, res.eo.opk, res.local)
        c_true, _ = eo_map_to_local(blk.eo_true.xyz, blk.eo_true.opk, res.local)
        eo_idx = [
            res.adjustment.names.index(f"{im} {c}")
            for im in res.eo.image_id
            for c in ("X0", "Y0", "Z0")
        ]
        eo_z.append((c_est - c_true).ravel() / res.adjustment.std_prior[eo_idx])
    p = 15
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], p * draws)
    assert lo < sum(d2) < hi, (sum(d2), lo, hi)
    z = np.concatenate(eo_z)
    # pooled RMS of normalised errors near 1 (correlated within a draw: loose 20 % band)
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.2


def test_converges_from_direct_georeferencing_errors_of_2_deg_and_10_m(blocks):
    blk = blocks["bauer"]
    rng = np.random.default_rng(9)
    start = replace(
        blk.eo_true,
        xyz=blk.eo_true.xyz + rng.normal(0, 10.0, blk.eo_true.xyz.shape),
        opk=blk.eo_true.opk + np.radians(rng.normal(0, 2.0, blk.eo_true.opk.shape)),
    )
    far = _run(blk, "bauer", eo=start, sigma=False)
    near = _run(blk, "bauer", eo=blk.eo_true, sigma=False)
    assert far.adjustment.converged and near.adjustment.converged
    s = near.adjustment.std
    assert np.all(np.abs(far.adjustment.x - near.adjustment.x) <= 1e-3 * s + 1e-9)


def test_without_orientations_the_block_grows_from_the_control(blocks):
    blk = blocks["jacobsen"]
    grown = bundle_adjust(
        [blk.camera],
        blk.observations,
        blk.ground,
        blk.mapping,
        options=BundleOptions(ap_model="jacobsen", **PLAIN),
    )
    ref = _run(blk, "jacobsen", eo=blk.eo_true, sigma=False)
    assert grown.adjustment.converged
    assert np.abs(grown.adjustment.x - ref.adjustment.x).max() <= 1e-3 * ref.adjustment.std.max()


def test_free_network_keeps_the_shape_of_the_controlled_block(blocks):
    """Inner constraints on the tie points (no control, approximate orientations): the same
    fit (v'Pv) and the same block shape (distances between object points) as with control
    points, up to the similarity the datum leaves free."""
    blk = blocks["lens_k1k2"]
    tie_only = GroundPoints.empty()
    checks = set(blk.ground.point_id)
    obs = blk.observations.subset([p not in checks for p in blk.observations.point_id])
    blk = replace(blk, observations=obs)
    free = bundle_adjust(
        [blk.camera],
        blk.observations,
        tie_only,
        blk.mapping,
        blk.eo_dg,
        options=BundleOptions(ap_model="none", estimate_interior=False, datum="inner", **PLAIN),
    )
    assert free.adjustment.converged and free.adjustment.n_constraints == 7
    mini = bundle_adjust(
        [blk.camera],
        blk.observations,
        tie_only,
        blk.mapping,
        blk.eo_dg,
        options=BundleOptions(ap_model="none", estimate_interior=False, datum="minimal", **PLAIN),
    )
    assert abs(free.adjustment.omega / mini.adjustment.omega - 1) < 1e-6
    a, b = free.local.map_to_enu(free.point_xyz), mini.local.map_to_enu(mini.point_xyz)
    da = np.linalg.norm(a[1:] - a[:-1], axis=1)
    db = np.linalg.norm(b[1:] - b[:-1], axis=1)
    # the datums differ by a similarity: the ratios of distances are one constant (the scale)
    ratio = da / db
    assert np.std(ratio) < 1e-5 * np.mean(ratio)


def test_observed_orientations_with_lever_arm_and_boresight(blocks):
    """GNSS/INS orientations observed with a constant lever arm (0.3, -0.2, 0.5 m, camera
    axes) and boresight (0.3, -0.2, 0.5 deg) error: both recovered within 3 sigma."""
    from lidarphoto.core.geometry.rotations import boresight_matrix, matrix_to_opk, opk_to_matrix
    from lidarphoto.core.photo.orientation import eo_local_to_map, eo_map_to_local

    blk = blocks["lens_k1k2"]
    rng = np.random.default_rng(4)
    lever = np.array([0.3, -0.2, 0.5])
    bore = np.radians([0.3, -0.2, 0.5])
    sig_p, sig_a = 0.03, np.radians(0.005)
    from lidarphoto.core.geometry.frames import LocalFrame

    local = LocalFrame.at_map_point(blk.mapping, blk.ground.xyz.mean(axis=0))
    c, M = eo_map_to_local(blk.eo_true.xyz, blk.eo_true.opk, local)
    # DESIGN.md: X_pc = X_obs + R_c^m lever, R_c^m = R_obs dR (so M_obs = dR M)
    Mobs = boresight_matrix(*bore) @ M
    cobs = c - np.einsum("nji,j->ni", M, lever) + rng.normal(0, sig_p, c.shape)
    om, ph, ka = matrix_to_opk(Mobs)
    Mobs = opk_to_matrix(
        om + rng.normal(0, sig_a, om.size),
        ph + rng.normal(0, sig_a, om.size),
        ka + rng.normal(0, sig_a, om.size),
    )
    xyz, opk = eo_local_to_map(cobs, Mobs, local)
    observed = replace(blk.eo_true, xyz=xyz, opk=opk)
    sigma = np.tile([sig_p] * 3 + [sig_a] * 3, (len(observed), 1))
    res = bundle_adjust(
        [blk.camera],
        blk.observations,
        blk.ground,
        blk.mapping,
        observed,
        sigma,
        options=BundleOptions(ap_model="lens_k1k2", estimate_mount=True, **PLAIN),
    )
    m = res.mount
    assert np.all(np.abs(m["lever_arm_m"] - lever) < 3 * m["lever_arm_std_m"]), m
    assert np.all(np.abs(m["boresight_rad"] - bore) < 3 * m["boresight_std_rad"]), m
    # along the optical axis the lever arm is a height shift the control barely separates
    assert np.all(m["lever_arm_std_m"][:2] < 0.15) and np.all(
        np.degrees(m["boresight_std_rad"]) < 0.01
    )


def test_ap_selection_drops_and_says_why(blocks):
    """Brown's 14 terms on a block with Bauer's distortion: the selection drops terms one at
    a time with their reasons, keeps the significant ones, and the check points stay as good
    as with the true family."""
    blk = blocks["bauer"]
    res = bundle_adjust(
        [blk.camera],
        blk.observations,
        blk.ground,
        blk.mapping,
        blk.eo_dg,
        blk.eo_sigma,
        options=BundleOptions(ap_model="brown"),
    )
    assert len(res.dropped) >= 5
    assert all(("insignificant" in why) or ("correlation" in why) for _, _, why in res.dropped)
    kept = [p for p in res.interior if p.is_ap and p.status == "estimated"]
    assert kept and all(p.significant for p in kept)
    dropped = {n for _, n, _ in res.dropped}
    assert all(p.status == "dropped" for p in res.interior if p.name in dropped)
    ref = _run(blk, "bauer")
    assert res.check.statistics()["rms_3d"] < 1.3 * ref.check.statistics()["rms_3d"] + 0.01


# ----------------------------------------------------------------------------- refusals


def _with(obs, keep=None, **changes):
    from lidarphoto.core.photo.observations import ImageObservations

    base = obs.subset(np.arange(len(obs)) if keep is None else keep)
    fields = {
        f: getattr(base, f)
        for f in ("image_id", "point_id", "pixels", "sigma_px", "type", "target_id")
    }
    fields.update(changes)
    n = len(fields["image_id"])
    return ImageObservations(**fields, rows=tuple(range(2, n + 2)), source="obs.csv")


def test_bad_tables_are_refused_with_file_and_row(blocks):
    blk = blocks["bauer"]
    obs = _with(blk.observations)
    opts = BundleOptions(**PLAIN)

    def run(o=obs, g=blk.ground, eo=blk.eo_dg, sig=blk.eo_sigma):
        return bundle_adjust(
            [blk.camera],
            o,
            g,
            blk.mapping,
            eo,
            sig,
            options=opts,
            eo_rows=tuple(range(2, len(eo) + 2)) if eo is not None else None,
            eo_source="eo.csv",
        )

    # an image of the EO table without observations
    extra = replace(
        blk.eo_dg,
        image_id=(*blk.eo_dg.image_id, "IMG_EMPTY"),
        time=np.r_[blk.eo_dg.time, 0.0],
        group=(*blk.eo_dg.group, ""),
        xyz=np.vstack([blk.eo_dg.xyz, blk.eo_dg.xyz[:1]]),
        opk=np.vstack([blk.eo_dg.opk, blk.eo_dg.opk[:1]]),
    )
    with pytest.raises(InputError, match=r"eo\.csv.*row 17.*IMG_EMPTY.*no observations"):
        run(eo=extra, sig=np.vstack([blk.eo_sigma, blk.eo_sigma[:1]]))
    # a tie point seen once
    tie = [i for i, p in enumerate(obs.point_id) if p.startswith("T")]
    first = tie[0]
    keep = np.array([i == first or obs.point_id[i] != obs.point_id[first] for i in range(len(obs))])
    with pytest.raises(
        InputError, match=rf"obs\.csv.*tie point '{obs.point_id[first]}'.*one image"
    ):
        run(o=_with(obs, keep))
    # a duplicated row
    dup = np.r_[np.arange(len(obs)), [5]]
    with pytest.raises(InputError, match=rf"row {len(obs) + 2}.*measured twice.*also row 7"):
        run(o=_with(obs, dup))
    # an unknown image
    ids = list(obs.image_id)
    ids[10] = "IMG_XX"
    with pytest.raises(InputError, match=r"row 12.*IMG_XX.*not in the exterior orientation"):
        run(o=_with(obs, image_id=tuple(ids)))
    # control points in another CRS: degrees, or far away
    deg = replace(
        blk.ground,
        xyz=np.column_stack(
            [
                np.full(len(blk.ground), -43.7),
                np.full(len(blk.ground), -22.75),
                blk.ground.xyz[:, 2],
            ]
        ),
    )
    with pytest.raises(InputError, match="degrees"):
        run(g=deg)
    moved = replace(
        blk.ground,
        xyz=blk.ground.xyz + [0.0, 1.0e6, 0.0],
        rows=tuple(range(2, 23)),
        source="ground.csv",
    )
    with pytest.raises(InputError, match=r"ground\.csv.*row 2.*km from the nearest image"):
        run(g=moved)


def test_unconnected_parts_are_named(blocks):
    """Remove every tie point that links the first strip to the others: the four images of
    strip 1 are named as a separate part."""
    blk = blocks["bauer"]
    obs = blk.observations
    strip1 = {i for i in set(obs.image_id) if i.startswith("IMG_01")}
    in1 = {}
    for im, p in zip(obs.image_id, obs.point_id):
        in1.setdefault(p, set()).add(im in strip1)
    links = {p for p, s in in1.items() if len(s) == 2}
    keep = np.array([p not in links for p in obs.point_id])
    sub = obs.subset(keep)
    with pytest.raises(
        InputError,
        match=r"unconnected parts.*IMG_0101, IMG_0102, IMG_0103, "
        r"IMG_0104 are not connected",
    ):
        bundle_adjust(
            [blk.camera],
            sub,
            blk.ground,
            blk.mapping,
            blk.eo_dg,
            blk.eo_sigma,
            options=BundleOptions(**PLAIN),
        )


def test_too_little_control_for_the_datum_is_refused(blocks):
    blk = blocks["bauer"]
    two = GroundPoints(
        blk.ground.point_id[:2], blk.ground.xyz[:2], blk.ground.sigma[:2], ("control", "control")
    )
    obs = blk.observations.subset(
        [p not in blk.ground.point_id[2:] for p in blk.observations.point_id]
    )
    obs = _with(obs, type=("tie",) * len(obs))
    with pytest.raises(InputError, match="three or more control points"):
        bundle_adjust(
            [blk.camera], obs, two, blk.mapping, blk.eo_dg, options=BundleOptions(**PLAIN)
        )
    # an image with two points only, without observed orientations
    o = blk.observations
    count = {p: o.point_id.count(p) for p in set(o.point_id)}
    in_img = [k for k, i in enumerate(o.image_id) if i == "IMG_0101"]
    keep_in = {
        k for k in in_img if count[o.point_id[k]] >= 3 and not o.point_id[k].startswith("GCP")
    }
    keep_in = set(sorted(keep_in)[:2])
    mask = np.array([(i != "IMG_0101") or (k in keep_in) for k, i in enumerate(o.image_id)])
    pts = [p for p, m in zip(o.point_id, mask) if m]
    mask &= np.array([pts.count(p) >= 2 for p in o.point_id])
    few = o.subset(mask)
    with pytest.raises((InputError, NotObservableError), match="IMG_0101"):
        bundle_adjust(
            [blk.camera], few, blk.ground, blk.mapping, blk.eo_dg, options=BundleOptions(**PLAIN)
        )


def test_observed_orientation_model_jacobian():
    """The analytic Jacobian of the observed-orientation model (lever arm and boresight)
    against central differences."""
    from lidarphoto.core.photo.bundle_model import _ObservedEOModel

    rng = np.random.default_rng(0)
    g = 6
    xl = np.column_stack(
        [
            rng.normal(0, 10, (g, 3)),
            rng.normal(0, 0.05, (g, 2)),
            rng.uniform(-3, 3, g),
            rng.normal(0, 0.3, (g, 3)),
            rng.normal(0, 0.01, (g, 3)),
        ]
    )
    model = _ObservedEOModel(np.zeros((g, 6)))
    _f, J = model(xl)
    for j in range(12):
        p, q = xl.copy(), xl.copy()
        p[:, j] += 1e-7
        q[:, j] -= 1e-7
        num = (model(p)[0] - model(q)[0]) / 2e-7
        assert np.abs(num - J[:, :, j]).max() < 1e-6, j


def test_two_cameras_each_get_their_own_interior_orientation(blocks, tmp_path):
    """The block split between two cameras (JSON {"cameras": [...]} and a camera per image):
    each camera's principal distance, principal point and k1, k2 are estimated from its own
    images and agree with the (shared) truth within 3 sigma."""
    from lidarphoto.core.io.camera import read_cameras_json, write_cameras_json

    blk = blocks["lens_k1k2"]
    cams = [replace(blk.camera, name="left"), replace(blk.camera, name="right")]
    write_cameras_json(tmp_path / "cams.json", cams)
    cams = read_cameras_json(tmp_path / "cams.json")
    assert [c.name for c in cams] == ["left", "right"]
    mapping = {im: ("left" if im < "IMG_03" else "right") for im in blk.eo_dg.image_id}
    res = bundle_adjust(
        cams,
        blk.observations,
        blk.ground,
        blk.mapping,
        blk.eo_dg,
        blk.eo_sigma,
        image_camera=mapping,
        options=BundleOptions(ap_model="lens_k1k2", **PLAIN),
    )
    assert set(res.cameras) == {"left", "right"}
    for p in res.interior:
        assert abs(p.value - _truth(blk, p.name)) < 3 * p.std, (p.camera, p.name)
    assert res.image_camera == tuple(mapping[i] for i in res.eo.image_id)
    with pytest.raises(InputError, match="has no camera"):
        bundle_adjust(
            cams,
            blk.observations,
            blk.ground,
            blk.mapping,
            blk.eo_dg,
            blk.eo_sigma,
            options=BundleOptions(**PLAIN),
        )


def test_planted_blunders_are_rejected_by_the_default_pipeline(blocks):
    """Twelve measurements moved by 8-30 px: the robust stage and data snooping reject all of
    them, and the APs come out as without them."""
    from lidarphoto.core.photo.observations import ImageObservations

    blk = blocks["bauer"]
    obs = blk.observations
    rng = np.random.default_rng(21)
    tie = np.array([k for k, p in enumerate(obs.point_id) if p.startswith("T")])
    bad = rng.choice(tie, 12, replace=False)
    px = obs.pixels.copy()
    px[bad] += rng.choice([-1, 1], (12, 2)) * rng.uniform(8, 30, (12, 2))
    dirty = ImageObservations(obs.image_id, obs.point_id, px, obs.sigma_px, obs.type, obs.target_id)
    res = bundle_adjust(
        [blk.camera],
        dirty,
        blk.ground,
        blk.mapping,
        blk.eo_dg,
        blk.eo_sigma,
        options=BundleOptions(ap_model="bauer", ap_selection=False),
    )
    assert set(bad) <= set(np.flatnonzero(res.rejected))
    clean = _run(blk, "bauer")
    for p, q in zip(res.interior, clean.interior):
        assert abs(p.value - q.value) < 0.5 * q.std, p.name
