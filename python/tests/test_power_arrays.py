"""`aloft.power` over numpy arrays: broadcasting, shapes, dtypes, speed, the GIL released."""

from __future__ import annotations

import threading
import time

import numpy as np

import aloft


def test_broadcast_shapes():
    airspeed = np.linspace(0.0, 15.0, 7)              # (7,)
    pitch = -np.linspace(0.0, 12.0, 3)[:, None]       # (3, 1)
    out = aloft.power(airspeed, 0.0, pitch, climb_rate=0.5)
    assert list(out) == aloft.POWER_KEYS
    for k, v in out.items():
        assert v.shape == (3, 7), k
        assert v.dtype == np.float64
    # Each element is the scalar call's answer.
    for i in range(3):
        for j in range(7):
            one = aloft.power(airspeed[j], 0.0, pitch[i, 0], 0.5)
            assert one["electrical_w"].shape == ()
            assert out["electrical_w"][i, j] == one["electrical_w"]


def test_scalars_lists_and_empty():
    assert aloft.power(5, 0, -5)["electrical_w"].shape == ()
    assert aloft.power([5, 6], [0, 0], [-5, -6])["thrust_n"].shape == (2,)
    empty = aloft.power(np.zeros((0, 4)), 0.0, 0.0)
    assert all(v.shape == (0, 4) for v in empty.values())


def test_non_contiguous_and_integer_inputs():
    a = np.arange(20, dtype=np.int64)[::2]             # strided ints
    got = aloft.power(a, 0, -a.astype(float))
    expected = aloft.power(a.astype(float).copy(), 0.0, -a.astype(float))
    assert np.array_equal(got["electrical_w"], expected["electrical_w"])


def test_million_states_well_under_half_a_second():
    n = 1_000_000
    rng = np.random.default_rng(1)
    airspeed = rng.uniform(0.0, 15.0, n)
    roll = rng.uniform(-10.0, 10.0, n)
    pitch = rng.uniform(-20.0, 5.0, n)
    climb = rng.uniform(-2.0, 2.0, n)
    aloft.power(airspeed[:1000], roll[:1000], pitch[:1000], climb[:1000])  # warm
    best = min(_timed(lambda: aloft.power(airspeed, roll, pitch, climb)) for _ in range(3))
    print(f"\naloft.power: 1e6 states in {best * 1e3:.0f} ms ({best * 1e3:.0f} ns/state)")
    assert best < 0.5


def _timed(f) -> float:
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


def test_gil_released_while_computing():
    """A Python thread keeps running while power() computes 4 million states."""
    n = 4_000_000
    a = np.full(n, 8.0)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.05)
    start = time.perf_counter()
    aloft.power(a, 0.0, -8.0)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # Held GIL: the counter would stall for the whole call (no tick inside it, bar the switch
    # interval). Released: it ticks every millisecond or so.
    assert end - start > 0.02
    assert len(during) >= 5, (len(during), end - start)
