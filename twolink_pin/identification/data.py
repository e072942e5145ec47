"""Logged runs: what identification starts from, read from a user's file or made by the toolkit.

A :class:`RunLog` holds sampled time ``t`` [s], joint positions ``q`` [rad], optionally the
velocities ``v`` [rad/s] the controller logged, and the joint torques ``tau`` [N·m] that drove
the arm. Files (``--data FILE``):

* **CSV** — a header row, then one row per sample; the columns, in any order::

      t, q1, …, qn, tau1, …, taun            (required; n = the robot's nv)
      v1, …, vn  (or dq1, …, dqn)            (optional: logged velocities, used as a check only)

  A column of another name is ignored (and listed in :attr:`RunLog.ignored_columns`).
  Separators ``,`` or ``;`` or tab; ``#`` starts a comment line.
* **NPZ** — arrays ``t`` (K,), ``q`` (K, n), ``tau`` (K, n) and optionally ``v`` (K, n).

:func:`read_log` refuses, with what is wrong and where: a missing column or array, a cell
that is not a finite number (data row and line of the file, column name), time that does
not increase strictly or jumps by more than :data:`MAX_GAP_STEPS` median steps (the row), and
fewer samples than :data:`MIN_SAMPLES` or than the caller needs for its number of parameters. Data rows are numbered from 1 (the header is
line 1 of the file when there are no comment lines).
"""

from __future__ import annotations

import csv
import io
import os
import zipfile
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.errors import InputFileError, InvalidParameterError, require_type
from twolink_pin.files import atomic_write, read_input_file

MAX_LOG_BYTES = 512 << 20
"""Largest log file read (512 MiB)."""
MAX_LOG_VALUES = MAX_LOG_BYTES // 8
"""Most numbers a log's arrays may hold once inflated (as many float64 as the file bound
allows bytes): a compressed archive that expands past that is refused before it is read."""
MIN_SAMPLES = 10
"""Fewest samples a log may have whatever the number of parameters."""
MAX_GAP_STEPS = 10.0
"""Longest gap between samples, in median steps, that a log may have (a bag's gaps are
interpolated across up to this); a longer one is refused: time that jumps (a clock reset, two
runs in one file) would be resampled into a log of a motion that never happened. A bag's
stamp this many steps before one already read is time that runs backwards."""
TIME_NAMES = ("t", "time")
"""Accepted names of the time column."""


@dataclass(frozen=True)
class RunLog:
    """A logged run (arrays read-only; K samples, n joints).

    Attributes:
        t: Time [s], shape (K,), strictly increasing.
        q: Joint positions [rad], shape (K, n).
        tau: Joint torques [N·m] that drove the arm, shape (K, n).
        v: Logged joint velocities [rad/s], shape (K, n), or None (identification estimates
            velocities from ``q`` either way; a logged ``v`` only checks that estimate).
        source: Where the data come from (a file path, or "simulated …").
        true_parameters: For simulated data, the true values of the identified parameters
            (base parameters, then viscous and Coulomb friction per joint), else None.
        ignored_columns: CSV columns that were not used.
        reference: The trajectory the arm was tracking, sampled at the log's times (a
            simulated log's excitation, or what a user gives): its noise-free regressor is the
            instrument of :func:`~twolink_pin.identification.least_squares.identify`; None if
            unknown.
    """

    t: np.ndarray
    q: np.ndarray
    tau: np.ndarray
    v: np.ndarray | None = None
    source: str = ""
    true_parameters: np.ndarray | None = field(default=None, repr=False)
    ignored_columns: tuple[str, ...] = ()
    reference: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        q, tau = np.asarray(self.q, dtype=float), np.asarray(self.tau, dtype=float)
        if t.ndim != 1 or q.ndim != 2 or q.shape[0] != t.size or tau.shape != q.shape:
            raise InvalidParameterError(
                "log", f"t {t.shape}, q {q.shape}, tau {tau.shape}", "t (K,), q (K, n) and tau (K, n)"
            )
        if self.v is not None and np.shape(self.v) != q.shape:
            raise InvalidParameterError("log.v", f"shape {np.shape(self.v)}", f"shape {q.shape} like q")
        if self.reference is not None and getattr(self.reference, "nv", None) != q.shape[1]:
            raise InvalidParameterError(
                "log.reference",
                getattr(self.reference, "nv", type(self.reference).__name__),
                f"a trajectory of {q.shape[1]} joints like q",
            )
        object.__setattr__(self, "t", readonly(t))
        object.__setattr__(self, "q", readonly(q))
        object.__setattr__(self, "tau", readonly(tau))
        object.__setattr__(self, "v", readonly_or_none(self.v))
        object.__setattr__(self, "true_parameters", readonly_or_none(self.true_parameters))

    @property
    def samples(self) -> int:
        """Number of samples K."""
        return int(self.t.size)

    @property
    def nv(self) -> int:
        """Number of joints n."""
        return int(self.q.shape[1])

    @property
    def duration(self) -> float:
        """``t[-1] − t[0]`` [s]."""
        return float(self.t[-1] - self.t[0])


def column_names(nv: int, velocities: bool = False) -> list[str]:
    """The CSV header :func:`write_log` writes: ``t, q1..qn, [v1..vn,] tau1..taun``."""
    names = ["t", *(f"q{j + 1}" for j in range(nv))]
    if velocities:
        names += [f"v{j + 1}" for j in range(nv)]
    return names + [f"tau{j + 1}" for j in range(nv)]


def _check_values(path: str, log: RunLog, names: dict[str, tuple[str, int | None]], line_of: Any) -> None:
    """Finite values and strictly increasing time; errors name the row and the column."""
    arrays = {"t": log.t, "q": log.q, "tau": log.tau}
    if log.v is not None:
        arrays["v"] = log.v
    for key, array in arrays.items():
        bad = ~np.isfinite(array)
        if bad.any():
            k = int(np.argwhere(bad)[0][0])
            j = int(np.argwhere(bad)[0][1]) if array.ndim == 2 else None
            column = next(c for c, (a, jj) in names.items() if a == key and jj == j)
            value = float(array[k] if j is None else array[k, j])
            raise InputFileError(path, f"{line_of(k)}, column '{column}': {value!r} is not a finite number")
    steps = np.diff(log.t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0]) + 1
        column = next(c for c, (a, _) in names.items() if a == "t")
        raise InputFileError(
            path,
            f"{line_of(k)}, column '{column}': t = {log.t[k]:.9g} s is not after the previous row's "
            f"{log.t[k - 1]:.9g} s (time must increase strictly)",
        )
    step = float(np.median(steps))
    jumps = np.flatnonzero(steps > MAX_GAP_STEPS * step)
    if jumps.size:
        k = int(jumps[0]) + 1
        column = next(c for c, (a, _) in names.items() if a == "t")
        raise InputFileError(
            path,
            f"{line_of(k)}, column '{column}': time jumps from {log.t[k - 1]:.9g} s to {log.t[k]:.9g} s, "
            f"{steps[k - 1] / step:.3g} times the median step {step:.6g} s: more than {MAX_GAP_STEPS:g} steps "
            "cannot be interpolated honestly (cut the log into the parts without such gaps)",
        )


def check_sample_count(path: str, samples: int, needed: int, what: str) -> None:
    """Raise unless ``samples >= max(MIN_SAMPLES, needed)``."""
    least = max(MIN_SAMPLES, needed)
    if samples < least:
        raise InputFileError(
            path, f"has {samples} samples; {what} needs at least {least} (more samples, or fewer parameters)"
        )


def _read_csv(path: Path, nv: int) -> RunLog:
    raw = read_input_file(path, MAX_LOG_BYTES, "a run log (.csv or .npz)")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise InputFileError(str(path), f"is not UTF-8 text (byte {err.start})") from None
    lines = text.splitlines()
    numbered = [
        (i + 1, line) for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise InputFileError(str(path), "is empty: expected a header row t, q1..qn, tau1..taun and data rows")
    header_line, header_text = numbered[0]
    delimiter = max((",", ";", "\t"), key=header_text.count)
    rows = list(csv.reader(io.StringIO("\n".join(line for _, line in numbered)), delimiter=delimiter))
    header = [h.strip() for h in rows[0]]
    expected = column_names(nv)
    index = {name.lower(): k for k, name in enumerate(header)}
    time_key = next((n for n in TIME_NAMES if n in index), None)
    required = ["t" if time_key is None else time_key, *expected[1:]]
    missing = [name for name in required if name.lower() not in index]
    if missing:
        raise InputFileError(
            str(path),
            f"line {header_line}: missing column{'s' if len(missing) > 1 else ''} "
            f"{', '.join(repr(m) for m in missing)} (expected {', '.join(expected)} for nv = {nv}, optionally "
            f"v1..v{nv}; found {', '.join(repr(h) for h in header) or 'nothing'})",
        )
    velocity_names = [f"v{j + 1}" for j in range(nv)]
    if not all(n in index for n in velocity_names):
        velocity_names = [f"dq{j + 1}" for j in range(nv)]
    has_v = all(n in index for n in velocity_names)
    used: dict[str, tuple[str, int | None]] = {required[0]: ("t", None)}
    used |= {f"q{j + 1}": ("q", j) for j in range(nv)}
    used |= {f"tau{j + 1}": ("tau", j) for j in range(nv)}
    if has_v:
        used |= {name: ("v", j) for j, name in enumerate(velocity_names)}
    columns = {name: index[name.lower()] for name in used}
    data_rows = rows[1:]
    line_numbers = [n for n, _ in numbered[1:]]

    def line_of(k: int) -> str:
        return f"data row {k + 1} (line {line_numbers[k]})"

    values = np.empty((len(data_rows), len(columns)))
    order = list(columns)
    for k, row in enumerate(data_rows):
        if len(row) != len(header):
            raise InputFileError(
                str(path), f"{line_of(k)}: {len(row)} fields where the header has {len(header)}"
            )
        for c, name in enumerate(order):
            cell = row[columns[name]].strip()
            try:
                values[k, c] = float(cell)
            except ValueError:
                raise InputFileError(
                    str(path), f"{line_of(k)}, column '{name}': {cell!r} is not a number"
                ) from None
    pick = {name: values[:, c] for c, name in enumerate(order)}
    log = RunLog(
        t=pick[required[0]],
        q=np.column_stack([pick[f"q{j + 1}"] for j in range(nv)]) if data_rows else np.zeros((0, nv)),
        tau=np.column_stack([pick[f"tau{j + 1}"] for j in range(nv)]) if data_rows else np.zeros((0, nv)),
        v=np.column_stack([pick[n] for n in velocity_names]) if has_v and data_rows else None,
        source=str(path),
        ignored_columns=tuple(h for h in header if h.lower() not in {n.lower() for n in used}),
    )
    check_sample_count(str(path), log.samples, MIN_SAMPLES, "identification")
    _check_values(str(path), log, {name: used[name] for name in order}, line_of)
    return log


def _read_npz(path: Path, nv: int) -> RunLog:
    raw = read_input_file(path, MAX_LOG_BYTES, "a run log (.csv or .npz)")
    from twolink_pin.simulation.storage import claimed_values  # the one header reader

    try:  # the sizes the arrays claim, from their headers, before anything is inflated
        claimed = claimed_values(io.BytesIO(raw))  # type: ignore[arg-type]
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
        raise InputFileError(
            str(path), f"is not a readable .npz archive ({type(exc).__name__}: {exc})"
        ) from None
    if claimed > MAX_LOG_VALUES:
        raise InputFileError(
            str(path),
            f"claims {claimed:.3g} numbers in its arrays; expected at most {MAX_LOG_VALUES:.3g} "
            f"({MAX_LOG_VALUES * 8 >> 20} MiB of float64) for a run log",
        )
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as archive:
            arrays = {k: np.asarray(archive[k]) for k in archive.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
        raise InputFileError(
            str(path), f"is not a readable .npz archive ({type(exc).__name__}: {exc})"
        ) from None
    missing = [k for k in ("t", "q", "tau") if k not in arrays]
    if missing:
        raise InputFileError(
            str(path),
            f"missing array{'s' if len(missing) > 1 else ''} {', '.join(repr(m) for m in missing)} "
            f"(expected t (K,), q (K, {nv}), tau (K, {nv}), optionally v; found {sorted(arrays) or 'nothing'})",
        )
    source = str(path)
    if "q_measured" in arrays and "v_measured" in arrays:
        # a saved simulation with sensor noise: what the law measured, as a real log records it
        arrays["q"], arrays["v"] = arrays.pop("q_measured"), arrays.pop("v_measured")
        source = f"{path} (q_measured, v_measured: what the law measured, with its sensor noise)"
    t = arrays["t"]
    if t.ndim != 1:
        raise InputFileError(str(path), f"array 't' has shape {t.shape}; expected (K,)")
    for key in ("q", "tau", "v"):
        if key in arrays and arrays[key].shape != (t.size, nv):
            raise InputFileError(
                str(path),
                f"array '{key}' has shape {arrays[key].shape}; expected ({t.size}, {nv}) like t and nv",
            )
        if key in arrays and not np.issubdtype(arrays[key].dtype, np.number):
            raise InputFileError(str(path), f"array '{key}' holds {arrays[key].dtype}, not numbers")
    if not np.issubdtype(t.dtype, np.number):
        raise InputFileError(str(path), f"array 't' holds {t.dtype}, not numbers")
    log = RunLog(t=t, q=arrays["q"], tau=arrays["tau"], v=arrays.get("v"), source=source)
    check_sample_count(str(path), log.samples, MIN_SAMPLES, "identification")
    names: dict[str, tuple[str, int | None]] = {"t": ("t", None)}
    for key in ("q", "tau", "v"):
        names |= {f"{key}[:, {j}] ({key}{j + 1})": (key, j) for j in range(nv)}
    _check_values(str(path), log, names, lambda k: f"sample {k} (index into t)")
    return log


def read_log(path: str | os.PathLike[str], nv: int) -> RunLog:
    """Read a run log for an arm of ``nv`` joints from a ``.csv`` or ``.npz`` file (see the
    module docstring for the format).

    Raises:
        InputFileError: the file cannot be read, or a column or value is missing or wrong
            (the message names the row and the column).
    """
    require_type(path, (str, os.PathLike), "path", "a file path (str or pathlib.Path)")
    file = Path(os.fspath(path))
    suffix = file.suffix.lower()
    if suffix == ".csv":
        return _read_csv(file, nv)
    if suffix == ".npz":
        return _read_npz(file, nv)
    raise InputFileError(str(file), f"has the suffix {suffix!r}; expected .csv or .npz")


def write_log(path: str | os.PathLike[str], log: RunLog) -> Path:
    """Write ``log`` as ``.csv`` (header :func:`column_names`, 17 significant digits) or
    ``.npz``, atomically: the file :func:`read_log` reads back."""
    file = Path(os.fspath(path))
    suffix = file.suffix.lower()
    if suffix == ".npz":
        buffer = io.BytesIO()
        arrays: dict[str, Any] = {"t": log.t, "q": log.q, "tau": log.tau}
        if log.v is not None:
            arrays["v"] = log.v
        np.savez_compressed(buffer, **arrays)
        with atomic_write(file, "wb") as f:
            f.write(buffer.getvalue())
        return file
    if suffix != ".csv":
        raise InvalidParameterError("path", str(file), "a .csv or .npz file name")
    parts = [log.t[:, None], log.q] + ([] if log.v is None else [log.v]) + [log.tau]
    table = np.hstack(parts)
    with atomic_write(file) as f:
        f.write(f"# {log.source or 'run log'}: t [s], q [rad], v [rad/s], tau [N·m]\n")
        f.write(",".join(column_names(log.nv, log.v is not None)) + "\n")
        np.savetxt(f, table, delimiter=",", fmt="%.17g")
    return file


def add_noise(log: RunLog, noise_q: float = 0.0, noise_tau: float = 0.0, seed: int = 0) -> RunLog:
    """``log`` with white Gaussian noise of standard deviation ``noise_q`` [rad] on ``q`` and
    ``noise_tau`` [N·m] on ``tau`` (independent per sample and joint), drawn from
    ``numpy.random.default_rng(seed)`` (q's noise first). Logged velocities are left alone.

    Raises:
        InvalidParameterError: a negative or non-finite standard deviation.
    """
    for name, value in (("noise_q", noise_q), ("noise_tau", noise_tau)):
        if not (np.isfinite(value) and value >= 0):
            raise InvalidParameterError(name, value, "a finite standard deviation >= 0")
    if noise_q == 0 and noise_tau == 0:
        return log
    rng = np.random.default_rng(seed)
    q = log.q + noise_q * rng.standard_normal(log.q.shape)
    tau = log.tau + noise_tau * rng.standard_normal(log.tau.shape)
    note = f"{log.source}, noise σ_q = {noise_q:g} rad, σ_τ = {noise_tau:g} N·m, seed {seed}"
    return replace(log, q=q, tau=tau, source=note)
