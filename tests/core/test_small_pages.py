"""numpy's huge-page advice is off while an adjustment runs and restored after, results
unchanged (core.lsq.adjustment.small_pages)."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.lsq import adjustment
from lidarphoto.core.lsq.adjustment import adjust, small_pages
from lidarphoto.core.lsq.model import GaussMarkovBlock

switch = adjustment._hugepage_switch()
pytestmark = pytest.mark.skipif(switch is None, reason="this numpy has no huge-page switch")


def _state() -> bool:
    assert switch is not None
    before = switch(True)  # read by setting, then put back
    switch(before)
    return bool(before)


@pytest.mark.parametrize("start", [True, False])
def test_off_inside_restored_after(start: bool) -> None:
    assert switch is not None
    old = switch(start)
    try:
        with small_pages():
            assert _state() is False
            with small_pages():  # nested: still off, the outer state kept
                assert _state() is False
            assert _state() is False
        assert _state() is start
        with pytest.raises(RuntimeError), small_pages():  # restored after an error too
            raise RuntimeError("x")
        assert _state() is start
    finally:
        switch(old)


def test_adjust_sees_it_off_and_fits_a_line() -> None:
    """A straight line through noisy points: the model records the advice at each call; the
    estimate agrees with the closed-form least-squares solution to 1e-12."""
    assert switch is not None
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 10.0, 50)
    y = 2.0 + 0.5 * t + rng.normal(0.0, 0.01, t.size)
    seen: list[bool] = []

    def line(xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        seen.append(_state())
        f = (xl[:, 0] + xl[:, 1] * t)[:, None]
        jac = np.stack([np.ones_like(t), t], axis=1)[:, None, :]
        return f, jac

    block = GaussMarkovBlock("line", y[:, None], np.full((t.size, 1), 0.01),
                             np.tile(np.array([0, 1]), (t.size, 1)), line)  # fmt: skip
    old = switch(True)
    try:
        res = adjust(np.zeros(2), ["a", "b"], [block])
        assert _state() is True
    finally:
        switch(old)
    assert seen and not any(seen)
    design = np.stack([np.ones_like(t), t], axis=1)
    expected = np.linalg.lstsq(design, y, rcond=None)[0]
    np.testing.assert_allclose(res.x, expected, rtol=0, atol=1e-12)


def test_overlapping_blocks_in_two_threads_restore_the_state_found_first() -> None:
    """Thread A enters, thread B enters, A leaves while B still runs, B leaves: the advice
    stays off until B leaves and is then what it was before A (a per-block save would have
    left it off for good: B saved A's "off")."""
    import threading

    assert switch is not None
    old = switch(True)
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    seen: dict[str, bool] = {}

    def run_a() -> None:
        with small_pages():
            a_in.set()
            b_in.wait(5)
        a_out.set()

    def run_b() -> None:
        a_in.wait(5)
        with small_pages():
            b_in.set()
            a_out.wait(5)
            seen["b after a left"] = _state()

    try:
        threads = [threading.Thread(target=run_a), threading.Thread(target=run_b)]
        for th in threads:
            th.start()
        for th in threads:
            th.join(10)
        assert seen == {"b after a left": False}
        assert _state() is True
    finally:
        switch(old)
