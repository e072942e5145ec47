"""A block's crossings from its extremes against the per-sample definition (``JointLimits.excess``):
the same first times and the same largest excess, bit for bit, with NaN, ±inf and one-sided limits."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.limits import JointLimits
from twolink_pin.limits.crossings import CROSSED_KINDS, RunningCrossings

INF = np.inf
VALUES = st.sampled_from([0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -2.0, 3.0, 1e-300, np.nan, INF, -INF])
BOUNDS = st.sampled_from([0.25, 1.0, 2.0, INF])


def _per_sample(limits: JointLimits, runs: int, blocks: list[tuple[np.ndarray, ...]]) -> dict[str, tuple]:
    """The definition, sample by sample: first time any excess > 0, largest excess (0 if none)."""
    out = {}
    for kind in CROSSED_KINDS:
        first, largest = np.full((runs, limits.nv), np.nan), np.zeros((runs, limits.nv))
        for t, *signals in blocks:
            values = signals[CROSSED_KINDS.index(kind)]
            for s in range(len(t)):
                excess = limits.excess(kind, values[s])
                newly = (excess > 0) & np.isnan(first)
                first[newly] = t[s]
                largest = np.maximum(largest, excess)
        out[kind.name] = (first, largest)
    return out


@settings(max_examples=150, deadline=None)
@given(
    data=st.data(),
    runs=st.integers(1, 3),
    nv=st.integers(1, 2),
    block_sizes=st.lists(st.integers(1, 4), min_size=1, max_size=3),
)
def test_block_crossings_are_the_per_sample_definition(
    data, runs: int, nv: int, block_sizes: list[int]
) -> None:
    lower = np.array(data.draw(st.lists(BOUNDS, min_size=nv, max_size=nv)))
    upper = np.array(data.draw(st.lists(BOUNDS, min_size=nv, max_size=nv)))
    velocity = np.array(data.draw(st.lists(BOUNDS, min_size=nv, max_size=nv)))
    effort = np.array(data.draw(st.lists(BOUNDS, min_size=nv, max_size=nv)))
    names = tuple(f"j{i}" for i in range(nv))
    limits = JointLimits(names, -lower, upper, velocity, np.full(nv, INF), effort)
    blocks, start = [], 0.0
    for size in block_sizes:
        t = start + 0.1 * np.arange(size)
        start = t[-1] + 0.1
        shape = (size, runs, nv)
        signals = [
            np.array(
                data.draw(st.lists(VALUES, min_size=size * runs * nv, max_size=size * runs * nv))
            ).reshape(shape)
            for _ in range(3)
        ]
        blocks.append((t, *signals))
    running = RunningCrossings(limits, runs)
    for block in blocks:
        running.add(*block)
    result = running.result()
    expected = _per_sample(limits, runs, blocks)
    for kind in CROSSED_KINDS:
        got = getattr(result, kind.name)
        first, largest = expected[kind.name]
        if not limits.given(kind).any():
            continue  # a kind no joint has is never checked
        np.testing.assert_array_equal(got.first_time, first)
        np.testing.assert_array_equal(got.excess, largest)
