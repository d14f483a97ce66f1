"""``teachfit learn skill`` and ``teachfit bench learning``: Johannsmeier et al.'s meta learning."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import (
    ConfirmOpt,
    HostOpt,
    RealtimeOpt,
    ReflexForceOpt,
    RobotOpt,
    append_markdown,
    check_reflex_force,
    console,
    guarded,
)
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import print_markdown, print_table
from teachfit.core.errors import NeedsAPerson
from teachfit.core.params import LearningError

if TYPE_CHECKING:
    from teachfit.bench.learning import LearningBench
    from teachfit.learning.launch import Launch
    from teachfit.learning.objective import SkillObjective
    from teachfit.learning.study import Study, TrialRecord

_CONTROLLER = typer.Option(help="controller: adaptive (learns its meta-parameters) or impedance")
_TASK_PARAM = o.TASK_PARAM


def _overrides(items: list[str] | None) -> tuple[tuple[str, float], ...]:
    return o.task_overrides(items, LearningError)


def _worker_counts(workers: str) -> list[int]:
    try:
        counts = [int(w) for w in workers.split(",") if w.strip()]
    except ValueError:
        counts = []
    if not counts or min(counts) < 1:
        raise LearningError(f"--scaling-workers wants counts >= 1 like 1,2,4, got {workers!r}")
    return counts


# long only by the declarations of its options: the body parses, calls and prints
@guarded
def learn_skill(
    task: Annotated[str, o.task("puzzle, key, peg, ... (teachfit tasks)")] = "puzzle",
    skill: Annotated[str, typer.Option(help="skill: built-in name or skill .toml")] = "peg-in-hole",
    method: Annotated[str, typer.Option(help="cmaes, pso, bo or lhs")] = "cmaes",
    trials: Annotated[int, typer.Option(min=1, help="trials in all (restored trials count)")] = 130,
    study: Annotated[
        str,
        typer.Option(
            help="study database: a file (SQLite) or a URL (postgresql://..., mysql://...)"
        ),
    ] = "runs/study.db",
    resume: Annotated[bool, typer.Option(help="continue a stored study")] = False,
    workers: o.Workers = None,
    ray: Annotated[
        str | None, typer.Option(help="run trials on Ray: 'local' or the address of a cluster")
    ] = None,
    controller: Annotated[str, _CONTROLLER] = "adaptive",
    seed: Annotated[int, o.seed("the set-up (hole estimate, starts) and of the learner")] = 0,
    starts: Annotated[int, o.starts("per trial (one execution each)")] = 4,
    setups: Annotated[int, o.setups("each trial is evaluated on (training stream)")] = 1,
    task_param: Annotated[list[str] | None, _TASK_PARAM] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            help="best parameters (TOML) for 'skill run --params' "
            "(default: beside a study file, STUDY.params.toml)"
        ),
    ] = None,
    plot: Annotated[Path | None, o.plot("the learning curve")] = None,
    traces: Annotated[Path | None, typer.Option(help="figure (PNG/PDF) of the parameters")] = None,
    best_plot: Annotated[
        Path | None,
        typer.Option(help="re-run the best parameters once and plot force and pose over time"),
    ] = None,
    robot: RobotOpt = "floating",
    host: HostOpt = None,
    realtime: RealtimeOpt = True,
    confirm: ConfirmOpt = False,
    reflex_force: ReflexForceOpt = None,
) -> None:
    """Learn a skill's parameters on a task by trials; every trial is stored at once."""
    from teachfit.learning.launch import LearnRequest, open_learning

    check_reflex_force(host, reflex_force)
    req = LearnRequest(
        task, skill, method, trials, study, resume, workers, ray, controller, seed, starts,
        _overrides(task_param), robot, host or "", realtime, setups, confirm, reflex_force,
    )  # fmt: skip
    launch = open_learning(req)
    for note in launch.notes:
        console.print(f"note: {note}")
    st, obj, n_w = launch.study, launch.objective, launch.workers
    where = f"Ray at {ray}" if ray else f"{'all cores' if n_w is None else n_w} worker(s)"
    per = f"{starts} start(s)" + (f" x {setups} set-ups" if setups > 1 else "")
    console.print(
        f"{method} on [bold]{task}[/] ({obj.space.dim} parameters, {per} per trial) -> "
        f"{st.where}; {st.n_restored} trial(s) restored; {where}"
    )
    if st.n_finished >= trials:
        console.print(
            f"[yellow]the study already holds {st.n_finished} trial(s) >= --trials "
            f"{trials}[/]: nothing to run; raise --trials to continue"
        )
    title = f"{method} on {task}, seed {seed}, {per} per trial"
    figures = (plot, traces, best_plot)
    _run_and_report(launch, out, figures, title)


def _run_and_report(
    launch: Launch,
    out: Path | None,
    figures: tuple[Path | None, Path | None, Path | None],
    title: str,
) -> None:
    """Run the trials with a progress bar, then report the best; Ctrl-C stops cleanly."""
    from teachfit.learning.launch import run_learning
    from teachfit.learning.runner import Interrupts
    from teachfit.learning.storage import params_path

    req, st = launch.request, launch.study
    method, task, trials = req.method, req.task, req.trials
    # one guard for the run and the report: a second Ctrl-C while the report is written
    # (after a first one ended the run) still aborts with the clear line below
    with Interrupts():
        try:
            best = [math.inf]
            with progress_bar() as bar:
                done = min(st.n_finished, trials)
                job = bar.add_task(f"{method} {task}", total=trials, completed=done)

                def progress(rec: TrialRecord) -> None:
                    if rec.feasible:
                        best[0] = min(best[0], rec.cost)
                    bar.update(job, advance=1, description=f"{method} {task} best {best[0]:.3f} s")

                rep = run_learning(launch, on_trial=progress)
            console.print(
                f"{rep.finished} trial(s) in {rep.wall_s:.1f} s ({rep.trials_per_s:.2f} "
                f"trials/s), {rep.failed} failed by crash/divergence; study holds "
                f"{st.n_finished}"
            )
            if not rep.interrupted and st.n_finished < trials:
                console.print(
                    f"[yellow]the {method} learner has nothing more to ask[/] (e.g. a Latin "
                    f"hypercube of {launch.options.get('n', '?')} points) after "
                    f"{st.n_finished} trials"
                )
            if st.n_finished:
                path = params_path(req.study) if out is None else out
                _report_best(st, launch.objective, path, *figures, title)
            if rep.interrupted:
                console.print(
                    f"[yellow]stopped[/] after {st.n_finished} stored trial(s); continue "
                    "with the same command and --resume"
                )
                raise typer.Exit(130)
        except NeedsAPerson as exc:  # a real arm's cell: the run stops, no trial charged
            console.print(
                f"[red]stopped[/]: {exc}; the {st.n_finished} finished trial(s) are stored"
            )
            raise typer.Exit(1) from None
        except KeyboardInterrupt:  # a second Ctrl-C / SIGTERM: running trials were dropped
            console.print(
                f"[red]interrupted again[/]: aborted; the {st.n_finished} finished trial(s) are "
                "stored, the running ones were dropped; continue with the same command and --resume"
            )
            raise typer.Exit(130) from None


def _report_best(
    st: Study,
    obj: SkillObjective,
    out: Path | None,
    plot: Path | None,
    traces: Path | None,
    best_plot: Path | None,
    title: str,
) -> None:
    from teachfit.viz import learning_figures as lf

    recs = st.trials()
    best = st.best()
    ok = sum(r.feasible for r in recs)
    rate = best.info.get("success_rate", float("nan"))
    console.print(
        f"best: trial {best.number + 1}, cost {best.cost:.3f} s, "
        f"{'feasible' if best.feasible else '[red]infeasible[/]'} "
        f"({100 * rate:.0f} % of its executions succeeded); {ok}/{len(recs)} "
        "trials feasible"
    )
    space = obj.space
    table = Table(title="best parameters", title_justify="left")
    for col in ("name", "value", "low", "high"):
        table.add_column(col)
    for name, v in best.params.items():
        d = space.domains[name]
        table.add_row(name, f"{v:.4g}", f"{d.low:.4g}", f"{d.high:.4g}")
    print_table(table)
    if out is not None:
        from teachfit.skills.params import write_params_toml

        head = f"best of {title}: cost {best.cost:.4f} s, trial {best.number + 1}"
        path = write_params_toml(out, best.params, head)
        task = obj.task
        console.print(
            f"parameters -> {path} (run them on set-ups never seen: teachfit skill run --task "
            f"{task} --params {path} --setups 20)"
        )
    if plot is not None:
        console.print(f"learning curve -> {lf.plot_study_curve(recs, plot, title)}")
    if traces is not None:
        learned = obj.trial().setup.skill.params.learned
        units = {name: p.unit for name, p in learned.items()}
        path = lf.plot_param_traces(recs, space, traces, title, units)
        console.print(f"parameter traces -> {path}")
    if best_plot is not None:
        outcome = obj.outcome(best.params)
        k = next((i for i, s in enumerate(outcome.successes) if s), 0)
        path = lf.plot_best_execution(outcome.traces[k], best_plot)
        console.print(f"best execution -> {path}")


# long by the declarations of its options; the grid, target and speed-up are in bench/
@guarded
def bench_learning(
    tasks: Annotated[
        str, typer.Option("--tasks", "--task", help="tasks, comma-separated (names or .toml)")
    ] = "puzzle,key,peg",
    methods: Annotated[
        str, typer.Option(help="methods, comma-separated: cmaes, pso, bo, lhs")
    ] = "cmaes,pso,bo,lhs",
    experiments: Annotated[int, typer.Option(min=1, help="learning runs per task and method")] = 2,
    trials: Annotated[int, typer.Option(min=1, help="trials per experiment")] = 60,
    workers: o.Workers = None,
    starts: Annotated[int, o.starts("per trial (one execution each)")] = 4,
    setups: Annotated[int, o.setups("each trial is evaluated on")] = 1,
    held_out: Annotated[
        int,
        typer.Option(
            min=0, help="held-out set-ups each experiment's best parameters then run on (0: none)"
        ),
    ] = 0,
    controller: Annotated[str, _CONTROLLER] = "adaptive",
    seed: Annotated[int, o.seed("the first experiment (experiment e uses seed + e)")] = 0,
    task_param: Annotated[list[str] | None, _TASK_PARAM] = None,
    plot: Annotated[Path | None, o.plot("learning curves like the paper's Fig. 6")] = Path(
        "out/bench_learning/curves.png"
    ),
    target: Annotated[
        bool,
        typer.Option(
            help="time a 130-trial x 4-start CMA-ES puzzle experiment against the 5-minute target"
        ),
    ] = True,
    speedup_trials: Annotated[
        int, typer.Option(min=0, help="trials of the 1-vs-N-worker speed-up study (0: skip)")
    ] = 24,
    markdown: o.Markdown = None,
    robot: RobotOpt = "floating",
    ray: Annotated[
        str | None, typer.Option(help="run trials on Ray: 'local' or the address of a cluster")
    ] = None,
    scaling: Annotated[
        bool,
        typer.Option(
            help="only measure trials/s with each of --scaling-workers workers (one run) "
            "and print the scaling"
        ),
    ] = False,
    scaling_workers: Annotated[str, typer.Option(help="worker counts of --scaling")] = "1,2,4",
    scaling_trials: Annotated[
        int, typer.Option(min=1, help="trials per worker of each --scaling count")
    ] = 6,
    random_rate: Annotated[
        int,
        typer.Option(
            min=0,
            help="only measure how often N random (Latin hypercube) parameter sets per "
            "experiment succeed on each task, and the throughput (0: run the grid)",
        ),
    ] = 0,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="folder keeping every experiment's study (SQLite): the same command "
            "resumes an interrupted grid from it",
        ),
    ] = Path("out/bench_learning/studies"),
) -> None:
    """Johannsmeier et al.'s Fig. 6 over tasks x methods x experiments, with timings."""
    import os

    from teachfit.learning.launch import check_ray_workers

    _worker_counts(scaling_workers)  # refused before any work, with --scaling or not
    check_ray_workers(ray, workers)
    if scaling:
        _bench_scaling(tasks, scaling_workers, scaling_trials, starts, seed, ray, markdown)
        return

    task_list = [t for t in tasks.split(",") if t]
    if random_rate:
        _bench_random(task_list, random_rate, experiments, starts, seed, task_param, workers)
        return
    res, text = _run_grid(
        task_list, [m for m in methods.split(",") if m], experiments, trials, workers, starts,
        controller, seed, task_param, robot, ray, out, (setups, held_out),
    )  # fmt: skip
    n_w = workers or os.cpu_count() or 1
    if target:
        text += _target_text(res, trials, starts, seed, workers, n_w)
    if speedup_trials > 0 and n_w > 1:
        text += _speedup_text(speedup_trials, n_w, seed, starts)
    print_markdown(text)  # tables drawn for the terminal; --markdown keeps the source
    if plot is not None:
        from teachfit.viz.learning_figures import plot_learning_curves

        bands = {(c.task, c.method): c.curve for c in res.cells}
        path = plot_learning_curves(
            bands, plot, f"best cost so far, mean and 95 % CI over {experiments} experiment(s)"
        )
        console.print(f"learning curves -> {path}")
    if markdown is not None:
        console.print(f"markdown appended to {append_markdown(markdown, text)}")


def _run_grid(
    task_list: list[str], method_list: list[str], experiments: int, trials: int,
    workers: int | None, starts: int, controller: str, seed: int, task_param: list[str] | None,
    robot: str, ray: str | None, out: Path | None, sets: tuple[int, int] = (1, 0),
) -> tuple[LearningBench, str]:  # fmt: skip
    """The grid with a progress bar, and its table headed by the command and its costs."""
    import os

    from teachfit.bench import learning as bl
    from teachfit.bench.learning_random import cpu_seconds

    total = len(task_list) * len(method_list) * experiments * trials
    ran = [0]
    cpu0 = cpu_seconds()

    def tick(label: str) -> None:
        ran[0] += 1
        bar.update(job, advance=1, description=label)

    with progress_bar() as bar:
        job = bar.add_task("learning", total=total)
        res = bl.run_learning_bench(
            task_list, method_list, experiments, trials, workers=workers, n_starts=starts,
            controller=controller, seed=seed, overrides=dict(_overrides(task_param)),
            on_trial=lambda label, _r: tick(label), robot=robot, ray=ray, studies=out,
            setups=sets[0], held_out=sets[1],
        )  # fmt: skip
    cpu = cpu_seconds() - cpu0
    extra = "".join(f" --task-param {p}" for p in task_param or [])
    extra += (f" --setups {sets[0]}" if sets[0] > 1 else "") + (
        f" --held-out {sets[1]}" if sets[1] else ""
    )
    done = sum(len(e.costs) for e in res.experiments)
    kept = f", {done - ran[0]} trials resumed from {out}: wall and trials/s count the others"
    execs = ran[0] * starts * sets[0]
    text = (
        f"`teachfit bench learning --tasks {','.join(task_list)} --methods "
        f"{','.join(method_list)} --experiments "
        f"{experiments} --trials {trials} --starts {starts}{extra}` ({res.workers} workers, "
        f"{os.cpu_count()} cores, {res.wall_s:.0f} s wall and {cpu:.0f} CPU-s in all, "
        f"{execs} executions: {execs / cpu if cpu > 0 else math.nan:.2f} per CPU-s, "
        f"learners included{kept if done > ran[0] else ''})\n\n" + bl.to_markdown(res)
    )
    return res, text


def _target_text(
    res: LearningBench, trials: int, starts: int, seed: int, workers: int | None, n_w: int
) -> str:
    """The 5-minute target of a 130-trial x 4-start CMA-ES puzzle experiment: the grid's own
    when it ran one, else one timed here."""
    from teachfit.bench import learning as bl
    from teachfit.learning.objective import SkillObjective

    done = [e for e in res.experiments if e.task == "puzzle" and e.method == "cmaes"]
    if done and trials == 130 and starts == 4 and done[0].restored:
        return "\nCMA-ES puzzle 5-minute target: not timed (its experiment was resumed)\n"
    if done and trials == 130 and starts == 4:
        wall = done[0].wall_s
    else:
        with console.status("130-trial x 4-start CMA-ES on puzzle"):
            obj = SkillObjective("puzzle", seed=seed)
            wall = bl.run_experiment(obj, "cmaes", 130, workers=workers).wall_s
    verdict = "meets" if wall <= 300 else "misses"
    return (
        f"\nCMA-ES, 130 trials x 4 starts on puzzle: {wall:.1f} s wall "
        f"({130 / wall:.2f} trials/s, {n_w} workers) -- {verdict} the 5-minute target\n"
    )


def _speedup_text(trials: int, n_w: int, seed: int, starts: int) -> str:
    """The speed-up of a CMA-ES puzzle study from 1 to ``n_w`` workers."""
    import os

    from teachfit.bench import learning_scaling as ls

    with console.status(f"speed-up: {trials} trials with 1 and {n_w} workers"):
        t1, tn, ratio = ls.speedup(trials=trials, workers=n_w, seed=seed, n_starts=starts)
    return (
        f"\nspeed-up, {trials}-trial x {starts}-start CMA-ES puzzle study "
        f"(fastest of 2 alternating runs each): 1 worker {t1:.1f} s, {n_w} workers "
        f"{tn:.1f} s: x{ratio:.2f} (ideal x{n_w}; 1-min load average "
        f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)\n"
    )


def _bench_scaling(
    tasks: str,
    workers: str,
    trials: int,
    starts: int,
    seed: int,
    ray: str | None,
    markdown: Path | None,
) -> None:
    """``bench learning --scaling``: trials/s with 1, 2, 4, ... workers, in one run."""
    import os

    from teachfit.bench import learning_scaling as ls

    counts = _worker_counts(workers)
    task = tasks.split(",")[0]
    with console.status(f"scaling: {task}, {trials} trial(s) per worker, {counts} workers"):
        rows = ls.scaling(
            counts, task=task, trials_per_worker=trials, n_starts=starts, seed=seed, ray=ray
        )
    where = f"Ray at {ray}" if ray else "a local process pool per count (start-up included)"
    text = (
        f"`teachfit bench learning --scaling --tasks {task} --scaling-workers {workers} "
        f"--scaling-trials {trials} --starts {starts}{f' --ray {ray}' if ray else ''}`: "
        f"Latin hypercube trials on {where}; this machine has {os.cpu_count()} cores, "
        f"1-min load average {os.getloadavg()[0]:.1f}\n\n" + ls.scaling_markdown(rows)
    )
    print_markdown(text)
    if markdown is not None:
        console.print(f"markdown appended to {append_markdown(markdown, text)}")


def _bench_random(
    tasks: list[str],
    trials: int,
    experiments: int,
    starts: int,
    seed: int,
    task_param: list[str] | None,
    workers: int | None,
) -> None:
    """``bench learning --random-rate N``: success of random parameters, and throughput."""
    import os

    from teachfit.bench import learning_random as lr

    rates = []
    with progress_bar() as bar:
        job = bar.add_task("random parameters", total=len(tasks) * experiments * trials)
        for task in tasks:

            def advance(_r: TrialRecord, t: str = task) -> None:
                bar.update(job, advance=1, description=t)

            rates.append(
                lr.random_rate(
                    task,
                    trials,
                    experiments,
                    n_starts=starts,
                    seed=seed,
                    overrides=dict(_overrides(task_param)),
                    workers=workers,
                    on_trial=advance,
                )
            )
    extra = "".join(f" --task-param {p}" for p in task_param or [])
    print_markdown(
        f"`teachfit bench learning --random-rate {trials} --tasks {','.join(tasks)} "
        f"--experiments {experiments} --starts {starts}{extra}` (1-min load average "
        f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)\n\n"
        + lr.random_rate_markdown(rates, workers or os.cpu_count() or 1)
    )
