"""A sweep's study and its cases: :class:`SweepConfig`, the draws of each run (:class:`Cases`),
the law of a chunk, the chunk size. The study as a whole: :mod:`twolink_pin.studies.sweep`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.run_spec import RunSpec
from twolink_pin.scenario import make_controller
from twolink_pin.simulation.config import joint_offsets

MAX_SAMPLES = 10_000_000
"""Largest number of runs of one sweep."""
MAX_CHUNK = 100_000
"""Largest number of runs advanced together (memory: ~2 kB per run and chunk)."""
AUTO_CHUNK = 1000
"""Largest chunk the automatic rule chooses (the batch engine's rate levels off there)."""
MIN_AUTO_CHUNK = 250
"""Smallest chunk the automatic rule chooses on a cluster, unless N is smaller: the batch
engine's rate at 250 runs is 80–90 % of its rate at 1000 (per-chunk setup amortised)."""
CHUNKS_PER_WORKER = 4
"""Chunks per worker thread the automatic rule aims at on a cluster: load balance, a
progress display that moves, and little lost when a worker dies."""


def auto_chunk(samples: int, workers: int | None = None) -> int:
    """The chunk size (runs per task) when none is given: chunks of (nearly) equal size, so
    that no worker or thread is left with a short last chunk.

    In-process (``workers`` None): ``ceil(N / ceil(N / 1000))`` — batches as large as the
    engine profits from (at most :data:`AUTO_CHUNK`), the runs split evenly (1200 runs: two
    of 600, both large enough for every thread, instead of 1000 and 200); progress comes
    from inside the chunk. On a cluster of ``workers`` worker threads: about
    :data:`CHUNKS_PER_WORKER` chunks each, of at least :data:`MIN_AUTO_CHUNK` runs — but
    never fewer chunks than workers (while N allows it), so that every worker has runs from
    the start (200 runs on 2 workers: two chunks of 100, not one of 200) — at most
    :data:`AUTO_CHUNK`, and a number of chunks that is a multiple of ``workers`` when the
    chunks are few (no last round with one worker busy and the others idle).
    """
    if workers is None:
        return math.ceil(samples / math.ceil(samples / AUTO_CHUNK))
    workers = max(1, workers)
    target = math.ceil(samples / (CHUNKS_PER_WORKER * workers))
    floor = min(MIN_AUTO_CHUNK, max(1, samples // workers))
    size = max(floor, min(target, AUTO_CHUNK))
    count = math.ceil(samples / size)
    if count < CHUNKS_PER_WORKER * workers:  # few chunks: whole rounds of every worker
        count = min(samples, math.ceil(count / workers) * workers)
    return math.ceil(samples / count)


@dataclass(frozen=True)
class GainRange:
    """A gain drawn uniformly in ``[low, high]`` for every run.

    Attributes:
        name: A field of the law's gains, optionally with a 1-based entry index (``kp2``).
        low: Lower bound, finite. high: Upper bound, finite, >= low.
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise InvalidParameterError(f"gain {self.name}", (self.low, self.high), "finite LO <= HI")

    @classmethod
    def parse(cls, text: str) -> GainRange:
        """``"NAME=LO:HI"`` (e.g. ``"kp=100:400"``)."""
        name, sep, rest = text.partition("=")
        low, sep2, high = rest.partition(":")
        try:
            if not (sep and sep2 and name.strip()):
                raise ValueError
            return cls(name.strip(), float(low), float(high))
        except ValueError:
            raise InvalidParameterError(
                "--gain", text, "NAME=LO:HI with numbers LO <= HI, e.g. kp=100:400"
            ) from None


def gain_target(cls: type[Controller], name: str) -> tuple[str, int | None]:
    """``(field, entry index or None)`` of gain ``name`` for law ``cls`` (``kp2`` → ("kp", 1)).

    Raises:
        InvalidParameterError: no such gain (the message lists the law's gains).
    """
    fields_ = cls.Gains.field_names()
    if name in fields_:
        return name, None
    stem = name.rstrip("0123456789")
    if stem in fields_ and stem != name and spec_of(cls.Gains, stem).per != "scalar":
        index = int(name[len(stem) :])
        if index >= 1:
            return stem, index - 1
    raise InvalidParameterError(
        "gain",
        name,
        f"one of the gains of '{cls.name}': {', '.join(fields_)} (vector gains also NAME1, NAME2, ...)",
    )


def law_reference(run: RunSpec) -> str:
    """The law of ``run`` as given (a registered name, ``file.py:Class``, ``module:Class``)."""
    law = run.law
    return law if isinstance(law, str) else f"{law.__module__}:{law.__qualname__}" if law else ""


@dataclass(frozen=True)
class SweepConfig:
    """A Monte Carlo study of one law (see the module docstring for the draws).

    Where it runs (in-process, a LocalCluster, a scheduler) is not part of the study: the
    results are the same. Nor is the chunking.

    Attributes:
        run: The run every case varies: the law (a registered name, ``file.py:Class`` or
            ``module:Class``), its fixed gains, ``λ``, the plant, the simulation (duration,
            step, control period, nominal ``q0_offset``; ``rk4`` only).
        samples: Number of runs N, 1 to :data:`MAX_SAMPLES`.
        seed: Seed of the draws, >= 0.
        q0_spread: Half-width of the uniform initial position error around the nominal
            ``simulation.q0_offset`` [rad], >= 0.
        param_error: Half-width of the relative parameter error δ, in [0, 1).
        gains: Gain ranges. A matrix gain (``osc``'s Kp, ``impedance``'s K) ``NAME=LO:HI`` is
            ``s I`` with s drawn, ``NAMEi=LO:HI`` the nominal matrix with entry (i, i) drawn
            (:func:`_matrix_draws`): per run an (N, k, k) stack, checked SPD.
        wrench_scale: ``(LO, HI)``: each run's factor on the plant's wrench (``--wrench``),
            drawn uniformly (after the other draws, so a study without it draws the same);
            None: every run feels the wrench as given.
        chunk: Runs advanced together (one task on a cluster; bounds memory), 1 to
            :data:`MAX_CHUNK`; None: :func:`auto_chunk`.
        threads: Threads of the batch engine per chunk (None: all cores in-process, one
            per task on a cluster — a worker process per core is the way to use cores there).
    """

    run: RunSpec
    samples: int
    seed: int = 0
    q0_spread: float = 0.0
    param_error: float = 0.0
    gains: tuple[GainRange, ...] = ()
    wrench_scale: tuple[float, float] | None = None
    chunk: int | None = None
    threads: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.run, RunSpec) or self.run.law is None:
            raise InvalidParameterError("run", self.run, "a RunSpec of one law")
        cls = self.run.law_class()
        for name, bound in (("samples", MAX_SAMPLES), ("chunk", MAX_CHUNK)):
            value = getattr(self, name)
            if name == "chunk" and value is None:
                continue
            if not (isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= bound):
                raise InvalidParameterError(name, value, f"a whole number from 1 to {bound}")
        if not (isinstance(self.seed, int) and not isinstance(self.seed, bool) and self.seed >= 0):
            raise InvalidParameterError("seed", self.seed, "a whole number >= 0")
        if not (math.isfinite(self.q0_spread) and self.q0_spread >= 0):
            raise InvalidParameterError("q0_spread", self.q0_spread, "a finite angle >= 0 rad")
        if not (math.isfinite(self.param_error) and 0 <= self.param_error < 1):
            raise InvalidParameterError("param_error", self.param_error, "a fraction in [0, 1)")
        if self.wrench_scale is not None:
            low, high = self.wrench_scale
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                raise InvalidParameterError("wrench_scale", self.wrench_scale, "finite factors LO <= HI")
            if self.run.plant.wrench is None:
                raise InvalidParameterError(
                    "wrench_scale",
                    self.wrench_scale,
                    "a wrench to scale (--wrench FX,FY,FZ[,MX,MY,MZ]@T0:T1)",
                )
        if self.run.simulation.method != "rk4":
            raise InvalidParameterError("method", self.run.simulation.method, "'rk4' (the batch engine)")
        names = [g.name for g in self.gains]
        if len(set(names)) != len(names):
            raise InvalidParameterError("gains", names, "each gain at most once")
        for g in self.gains:
            gain_target(cls, g.name)
        if self.run.lam is not None and not cls.takes("lam"):
            raise InvalidParameterError("lambda", self.run.lam, f"no λ for controller '{cls.name}'")


# -- the cases ---------------------------------------------------------------------------------


class Cases:
    """The drawn cases of runs ``start .. stop − 1``: arrays with one row per run."""

    def __init__(self, config: SweepConfig, robot: RobotModel, start: int, stop: int) -> None:
        nv, n_p = robot.nv, robot.parameter_map.size
        nominal = joint_offsets("q0_offset", config.run.simulation.q0_offset, robot.profile.q0_offset, nv)
        n = stop - start
        self.q0_offset = np.empty((n, nv))
        """``q(0) − q_d(0)`` [rad], shape (n, nv)."""
        self.param_factor = np.empty((n, n_p))
        """``1 + δ`` per parameter, shape (n, n_p)."""
        self.gains = {g.name: np.empty(n) for g in config.gains}
        """Drawn value of each gain range, shape (n,) each."""
        self.wrench_scale = np.ones(n)
        """Each run's factor on the plant's wrench, shape (n,) (1 unless drawn)."""
        for r, i in enumerate(range(start, stop)):
            rng = np.random.default_rng(np.random.SeedSequence(config.seed, spawn_key=(i,)))
            self.q0_offset[r] = nominal + rng.uniform(-config.q0_spread, config.q0_spread, nv)
            self.param_factor[r] = 1.0 + rng.uniform(-config.param_error, config.param_error, n_p)
            for g in config.gains:
                self.gains[g.name][r] = rng.uniform(g.low, g.high)
            if config.wrench_scale is not None:  # last: the draws above are those of a study without it
                self.wrench_scale[r] = rng.uniform(*config.wrench_scale)


CHECK_CHUNK = 1000
"""Runs whose drawn gains :func:`check_draws` checks at once."""


def check_draws(config: SweepConfig, robot: RobotModel, base: Controller) -> None:
    """Refuse a study with a drawn gain ``simulate`` would refuse, before any run: every run's
    draws (the same draws the runs make: each run's stream is its own) build the law through
    :func:`chunk_law`, the runs' own path, so with the checks of a value given to ``simulate``
    (``--gain kp=0:1e-300`` on ``osc``: ``kp ≈ 1e-301 I`` is refused here, not run). A
    ``positive`` gain's range from 0 passes while no draw falls below 1e-12.

    Raises:
        InvalidParameterError: ``--gain NAME=LO:HI``, the first run with a refused draw, its
            drawn values and what the law refused.
    """
    if not config.gains:
        return
    for start in range(0, config.samples, CHECK_CHUNK):
        stop = min(start + CHECK_CHUNK, config.samples)
        try:
            chunk_law(config, robot, Cases(config, robot, start, stop), base)
        except InvalidParameterError:
            for run in range(start, stop):  # name the first run refused
                cases = Cases(config, robot, run, run + 1)
                try:
                    chunk_law(config, robot, cases, base)
                except InvalidParameterError as exc:
                    ranges = " ".join(f"{g.name}={g.low:g}:{g.high:g}" for g in config.gains)
                    drawn = ", ".join(f"{name} = {value[0]:g}" for name, value in cases.gains.items())
                    raise InvalidParameterError(
                        f"--gain {ranges}",
                        f"run {run}: {drawn}",
                        f"draws '{type(base).name}' takes, as simulate checks a value ({exc})",
                    ) from None
            raise


def _matrix_draws(config: SweepConfig, cases: Cases, base: Controller) -> dict[str, np.ndarray]:
    """The drawn matrix gains of the chunk's runs, shape (n, k, k) each.

    ``NAME=LO:HI`` draws s and gives ``s I`` (s is the gain's value, as for a scalar gain:
    ``--gain kp=50:150`` on ``osc`` is Kp = s I); ``NAMEi=LO:HI`` draws diagonal entry
    (i, i) of the law's nominal matrix (its resolved gain), the others kept; both together
    give ``s I`` with the drawn entries. The gains check each run's matrix (symmetric
    positive definite) when the law is built.
    """
    cls = type(base)
    n = len(cases.q0_offset)
    out: dict[str, np.ndarray] = {}
    targets = [(g, *gain_target(cls, g.name)) for g in config.gains]
    for g, key, index in sorted(targets, key=lambda target: target[2] is not None):  # NAME before NAMEi
        if not spec_of(cls.Gains, key).matrix:
            continue
        if key not in out:
            nominal = np.asarray(getattr(base.gains, key), dtype=float)
            k = nominal.shape[-1] if nominal.ndim == 3 else 1
            out[key] = np.array(np.broadcast_to(nominal.reshape(-1, k, k), (n, k, k)))
        current = out[key]
        k = current.shape[-1]
        drawn = cases.gains[g.name]
        if index is None:
            current[:] = drawn[:, None, None] * np.eye(k)
        elif index < k:
            current[:, index, index] = drawn
        else:
            raise InvalidParameterError(
                "gain", g.name, f"a diagonal entry from 1 to {k} of the {k}×{k} matrix"
            )
    return out


def chunk_law(config: SweepConfig, robot: RobotModel, cases: Cases, base: Controller) -> Controller:
    """One law object for the chunk: drawn gains and believed parameters per run."""
    cls = type(base)
    n = len(cases.q0_offset)
    gains: dict[str, Any] = dict(_matrix_draws(config, cases, base))
    for g in config.gains:
        key, index = gain_target(cls, g.name)
        if spec_of(cls.Gains, key).matrix:
            continue  # drawn above
        drawn = cases.gains[g.name][:, None]
        if index is None:
            gains[key] = drawn if spec_of(cls.Gains, key).per != "scalar" else drawn[:, 0]
            continue
        current = gains.get(key)
        if current is None:
            width = robot.nv if spec_of(cls.Gains, key).per == "joint" else base.state_size
            current = np.array(np.broadcast_to(np.asarray(getattr(base.gains, key), dtype=float), (n, width)))
        if index >= current.shape[1]:
            raise InvalidParameterError("gain", g.name, f"an entry index from 1 to {current.shape[1]}")
        current[:, index] = drawn[:, 0]
        gains[key] = current
    believed = None
    if config.param_error > 0:
        believed = np.asarray(robot.p) * cases.param_factor
    resolved = {k: v for k, v in base.gains.values().items() if k not in gains}
    return make_controller(
        cls,
        robot,
        gains={**resolved, **gains},
        friction=config.run.law_friction(cls, robot),
        model_parameters=believed,
    )
