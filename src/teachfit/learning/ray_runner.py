"""Run a study's trials on a Ray cluster (optional extra: ``pip install teachfit[ray]``).

The same contract as :func:`~teachfit.learning.runner.run_study`: trials are asked in this
process, evaluated as Ray tasks (one CPU each) and stored here the moment each finishes, so a
killed driver resumes from the study database. Each Ray task fails on its own: an exception
or a non-finite cost in the objective, or a worker process that dies, fails only that trial
(stored at the study's penalty). SIGINT / SIGTERM: the first stops asking and lets running
trials finish; a second cancels them and raises ``KeyboardInterrupt``.

``address``: ``"local"`` starts a private local Ray instance (``workers`` CPUs, default all
cores) and shuts it down afterwards. Its processes listen on 127.0.0.1 only (Ray would pick
the address other machines reach this one at, and listen on all interfaces), and they end
with this process even after ``kill -9`` (:mod:`teachfit.learning.ray_reaper`). Anything else
(``"auto"``, ``"HOST:PORT"``, ``"ray://HOST:10001"``) connects to a running cluster. If Ray is
already initialised in this process it is used as it is. The objective must be picklable and
importable on the workers (e.g. :class:`~teachfit.learning.objective.SkillObjective` with
teachfit installed there).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import socket
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any

from teachfit.core.params import LearningError
from teachfit.learning.base import Candidate, TrialResult
from teachfit.learning.ray_reaper import Reaper
from teachfit.learning.runner import POLL_S, Interrupts, Objective, RunReport, evaluate
from teachfit.learning.study import Study, TrialRecord

#: the address a local Ray instance listens on
LOOPBACK = "127.0.0.1"

_NO_RAY = "--ray needs the optional Ray extra: pip install 'teachfit[ray]' (or ray>=2.9)"


def import_ray() -> ModuleType:
    """The ``ray`` module, or a :class:`LearningError` saying how to get it."""
    try:
        return importlib.import_module("ray")
    except ImportError as exc:
        raise LearningError(_NO_RAY) from exc


def _host_port(address: str) -> tuple[str, int] | None:
    """``(host, port)`` of a cluster address; ``None`` for ``local`` and ``auto``."""
    if address in ("", "local", "auto"):
        return None
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise LearningError(f"a Ray address is 'local', 'auto' or HOST:PORT, got {address!r}")
    return host, int(port)


def check_ray(address: str) -> None:
    """Refuse, before any work, a malformed Ray ``address`` or a missing Ray (one line)."""
    _host_port(address)
    if importlib.util.find_spec("ray") is None:
        raise LearningError(_NO_RAY)


def _check_reachable(address: str, timeout: float = 5.0) -> None:
    """Fail fast on a ``HOST:PORT`` (or ``ray://HOST:PORT``) nobody listens on: Ray itself
    retries a missing head node for minutes."""
    where = _host_port(address)
    if where is None:
        return
    host, port = where
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except OSError as exc:
        raise LearningError(f"no Ray cluster reachable at {address!r}: {exc}") from exc


@contextmanager
def _loopback(ray: ModuleType) -> Iterator[None]:
    """Within: Ray gives a node it starts the loopback address (as it does on macOS and
    Windows), not the one other machines reach it at; its servers then listen on 127.0.0.1."""
    consts = getattr(getattr(ray, "_private", None), "ray_constants", None)
    was = getattr(consts, "ENABLE_RAY_CLUSTER", None)
    if consts is not None and was is not None:
        consts.ENABLE_RAY_CLUSTER = False
    try:
        yield
    finally:
        if consts is not None and was is not None:
            consts.ENABLE_RAY_CLUSTER = was


def _start_local(ray: ModuleType, workers: int | None, kwargs: dict[str, Any]) -> Reaper:
    """Start a local instance on 127.0.0.1, watched by a :class:`Reaper` (returned)."""
    reaper = Reaper()
    try:
        with _loopback(ray):
            # trials are this instance's work: Ray starts its workers at nice 15, where beside
            # any busy process at normal priority they get next to no CPU (the 12-trial test
            # study beside three busy processes on 2 cores: 347 s, 160 s of it per worker
            # start; at nice 0 27 s, 15 s alone); a cluster's own settings are left alone
            ray.init(
                num_cpus=workers or os.cpu_count() or 1,
                _node_ip_address=LOOPBACK,
                dashboard_host=LOOPBACK,
                _system_config={"worker_niceness": 0},
                **kwargs,
            )
        reaper.note()  # the instance's processes: from now on none outlives this one
        node = ray.util.get_node_ip_address()
        if node != LOOPBACK:
            raise LearningError(
                f"Ray {ray.__version__} gave the local instance the address {node}, not "
                f"{LOOPBACK}: start a cluster on {LOOPBACK} (ray start --head "
                f"--node-ip-address {LOOPBACK}) and give its address to --ray"
            )
    except BaseException:
        ray.shutdown()
        reaper.stop()
        raise
    return reaper


def _init(ray: ModuleType, address: str, workers: int | None) -> tuple[bool, Reaper | None]:
    """Initialise Ray unless it is: ``(started, reaper)``, ``started`` if this call started
    or connected it (and must shut it down), ``reaper`` watching a local instance it started."""
    if ray.is_initialized():
        return False, None
    kwargs: dict[str, Any] = dict(
        include_dashboard=False, log_to_driver=False, configure_logging=False
    )
    os.environ.setdefault("RAY_DEDUP_LOGS", "0")
    _check_reachable(address)
    try:
        if address in ("", "local"):
            return True, _start_local(ray, workers, kwargs)
        ray.init(address=address, **kwargs)
    except LearningError:
        raise
    except Exception as exc:  # connection refused, bad address, ...
        raise LearningError(f"cannot start or reach Ray at {address!r}: {exc}") from exc
    return True, None


def run_study_ray(
    study: Study,
    objective: Objective,
    budget: int,
    address: str = "local",
    workers: int | None = None,
    handle_signals: bool = True,
    on_trial: Callable[[TrialRecord], None] | None = None,
) -> RunReport:
    """Run trials of ``study`` on Ray until it holds ``budget`` finished trials.

    ``workers``: trials in flight at once (default: the cluster's CPUs).
    """
    if budget < 0:
        raise LearningError(f"budget must be >= 0, got {budget}")
    if workers is not None and workers < 1:
        raise LearningError(f"workers must be >= 1 with Ray, got {workers}")
    ray = import_ray()
    t0 = time.perf_counter()
    started, reaper = _init(ray, address, workers)
    restored, here = study.n_finished, study.n_here
    trials = _RayTrials(ray, study, budget, on_trial)
    try:
        trials.start(objective, workers)
        with Interrupts(handle_signals) as sig:
            trials.run(sig)
            interrupted = sig.stop
    except BaseException:
        trials.cancel()
        raise
    finally:
        if started:
            ray.shutdown()
        if reaper is not None:
            reaper.stop()  # what the shutdown left of the local instance is killed
    elapsed = time.perf_counter() - t0
    return RunReport(restored, study.n_here - here, trials.failed, interrupted, elapsed)


class _RayTrials:
    """The trials of one :func:`run_study_ray` call: asked from ``study``, in flight as Ray
    tasks (``pending``: task reference -> candidate), told to ``study`` as they finish."""

    def __init__(
        self,
        ray: ModuleType,
        study: Study,
        budget: int,
        on_trial: Callable[[TrialRecord], None] | None,
    ) -> None:
        self.ray, self.study, self.budget, self.on_trial = ray, study, budget, on_trial
        self.failed = 0  # trials told as errors
        self.pending: dict[Any, Candidate] = {}

    def start(self, objective: Objective, workers: int | None) -> None:
        """Size the trials in flight (``workers``, or the cluster's CPUs), declare the Ray
        task and ship the objective to the cluster once."""
        ray = self.ray
        self.slots = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        self.task = ray.remote(num_cpus=1, max_retries=0)(evaluate)
        self.obj_ref = ray.put(objective)

    def run(self, sig: Interrupts) -> None:
        """Keep the slots filled and tell finished trials until the study is settled or a
        signal stops the asking and the trials in flight have finished."""
        while True:
            self._fill(sig)
            if not self.pending:
                if sig.stop or self.study.settled(self.budget):
                    break
                time.sleep(POLL_S)  # other processes run trials this learner waits for
                continue
            self._tell_finished()

    def _fill(self, sig: Interrupts) -> None:
        """Ask and submit candidates while slots are free (and no signal came)."""
        while not sig.stop and len(self.pending) < self.slots:
            cand = self.study.ask(self.budget)
            if cand is None:
                break
            self.pending[self.task.remote(self.obj_ref, self.study.params_of(cand))] = cand

    def _tell_finished(self) -> None:
        """Wait up to 0.2 s for a trial to finish and tell it to the study."""
        done, _ = self.ray.wait(list(self.pending), num_returns=1, timeout=0.2)
        for ref in done:
            cand = self.pending.pop(ref)
            rec = self.study.tell(cand, *self._outcome(ref))
            if rec is None:
                continue  # the claim was lost to another process, which runs it
            self.failed += rec.outcome == "error"
            if self.on_trial is not None:
                self.on_trial(rec)

    def _outcome(self, ref: Any) -> tuple[TrialResult | None, str]:
        """The finished task's (result, error); a worker that died or was lost is an error."""
        result: TrialResult | None
        try:
            result, error = self.ray.get(ref)
        except self.ray.exceptions.RayError as exc:  # the worker died, or was lost
            why = str(exc).strip().splitlines()[-1:] or [""]
            result, error = None, f"Ray worker failed: {type(exc).__name__}: {why[0]}"
        return result, error

    def cancel(self) -> None:
        """Cancel the trials in flight and give up their claims: other processes may run
        our unfinished trials at once."""
        for ref in self.pending:
            self.ray.cancel(ref, force=True)
        self.study.abandon()
