"""``agentchord bench``: the paper's comparisons, one record per episode, resumable, local or on Ray."""

from __future__ import annotations

import math
import time
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

from agentchord.cli.support import EXIT_INTERNAL, BadInput, catches_sigterm

TABLE_I_TASKS = "single_arm_pour_water,dual_arm_pour_water,rearrange_table"


class EpisodesMetAnOutage(click.ClickException):
    """Some episodes could not reach their LLM (recorded, left out of the tables, run again on a rerun):
    exit status 1, the sweep is not complete."""

    exit_code = 1

    def show(self, file=None) -> None:
        click.echo(f"agentchord: {self.format_message()}", err=True)


class EpisodesStoppedOnErrors(click.ClickException):
    """Some episodes stopped on an internal error (recorded, left out of the tables): exit status 3."""

    exit_code = EXIT_INTERNAL

    def show(self, file=None) -> None:
        click.echo(f"agentchord: {self.format_message()}", err=True)


def _csv_list(value: str) -> list[str]:
    # A name given twice is one task or method (it would otherwise be counted twice in the header).
    return list(dict.fromkeys(part.strip() for part in value.split(",") if part.strip()))


def _probabilities(ctx, param, value: str | None) -> list[float] | None:
    if value is None:
        return None
    out = []
    for part in _csv_list(value):
        try:
            p = float(part)
        except ValueError:
            raise click.BadParameter(f"{part!r} is not a number") from None
        if not math.isfinite(p) or not 0.0 <= p <= 1.0:
            raise click.BadParameter(f"{part!r} is not a probability in [0, 1]")
        out.append(p)
    if not out:
        raise click.BadParameter("give at least one probability, e.g. 0.05,0.10")
    return sorted(set(out))


def _latency(ctx, param, value: str | None):
    from agentchord.execution.reasoning import parse_latency

    try:
        return parse_latency(value or "tokens")
    except ValueError as error:
        raise click.BadParameter(str(error)) from None


@click.command("bench")
@click.option("--tasks", default=TABLE_I_TASKS, show_default=True,
              help="Comma-separated tasks (`agentchord tasks`), or paper (the paper's six), or all.")
@click.option("--methods", default=None, help="Comma-separated methods (default: all seven, in the paper's order, "
              "AgentChord with its sequential plan beside it).")
@click.option("--p", "ps", callback=_probabilities,
              help="Drop probabilities, comma-separated; without --p or --protocol: 0.05,0.10, Table I's two "
                   "(Fig. 4: 0,0.05,0.1,0.2,0.3).")
@click.option("--protocol", type=click.Choice(("real", "stress")), default=None, help="A disturbance protocol instead of --p (Table II: real).")
@click.option("--trials", type=click.IntRange(1, 10000), default=20, show_default=True, help="Seeds per task, method and condition.")
@click.option("--seed", "first_seed", type=click.IntRange(0, 2**31), default=0, show_default=True, help="Seeds run from here.")
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False), help="Sweep directory: records.jsonl, tables/, figures/. "
              "Rerun with the same --out to resume.")
@click.option("--backend", type=click.Choice(("local", "ray")), default="local", show_default=True,
              help="local: a process pool over all cores; ray: episodes as Ray tasks.")
@click.option("--ray-address", default=None, help="Join this Ray cluster (e.g. ray://head:10001 or auto); default: a local Ray instance.")
@click.option("--workers", type=click.IntRange(1, 256), default=None, help="Processes (local) or CPUs (local Ray); default: one per core.")
@click.option("--latency", callback=_latency, default=None,
              help="The reasoning latency model: tokens (the default: 0.45 s to first token + output tokens / 120 per s + "
                   "0.9 s per image, 4 calls at once; set any of ttft=,rate=,image=,concurrency=) or flat seconds per "
                   "call, e.g. plan=7,vqa=1.5,vlm=3.5 (the tables before the token model). Sources in docs/results.md.")
@click.option("--vqa-miss", type=click.FloatRange(0.0, 1.0), default=0.0, show_default=True, help="Probability a VQA query misses a failure.")
@click.option("--vqa-false-alarm", type=click.FloatRange(0.0, 1.0), default=0.0, show_default=True,
              help="Probability a VQA query reports a failure that is not there.")
@click.option("--doremi-every", type=click.IntRange(1, 10000), default=75, show_default=True, help="DoReMi's VQA period in control ticks (50 Hz).")
@click.option("--reasoner", type=click.Choice(("rules", "llm")), default="rules", show_default=True,
              help="rules: the library graphs, planning calls charged the modelled latency; llm: every method plans "
                   "from the instruction with the LLM of AGENTCHORD_LLM_* and is charged what its calls measured.")
@catches_sigterm
def bench_command(tasks, methods, ps, protocol, trials, first_seed, out_dir, backend, ray_address, workers, latency, vqa_miss,
                  vqa_false_alarm, doremi_every, reasoner) -> None:
    """Every method on the same seeded episodes; records as they finish, then tables and figures.

    \b
    Table I:  agentchord bench --p 0.05,0.10 --trials 20 --out out/table1
    Table II: agentchord bench --tasks paper --protocol real --trials 20 --out out/table2
    Fig. 4:   agentchord bench --tasks single_arm_pour_water --p 0,0.05,0.1,0.2,0.3 --out out/stress
    """
    from agentchord.bench.exceptions import BenchError
    from agentchord.bench.store import RecordStore
    from agentchord.bench.sweep import Condition, SweepConfig, describe, is_error, is_outage, sweep_keys
    from agentchord.execution.methods import METHODS
    from agentchord.execution.reasoning import ReasoningConfig
    from agentchord.sim.tasks import SIM_TASKS

    from agentchord.bench.tables import TASK_TITLES
    from agentchord.guard import OutputPathError
    from agentchord.guard.outputs import check_output_folder

    try:
        check_output_folder(out_dir, "--out")
    except OutputPathError as error:
        raise BadInput(str(error)) from None

    from agentchord.library import library_tasks

    # A sweep runs each task's library graph (or plans its library instruction): "all" is every task that has one.
    runnable = [t for t in SIM_TASKS if t in library_tasks()]
    aliases = {"all": runnable, "paper": list(TASK_TITLES)}
    task_names = aliases.get(tasks.strip(), None) or _csv_list(tasks)
    unknown = [t for t in task_names if t not in SIM_TASKS]
    if unknown or not task_names:
        raise click.BadParameter(f"unknown task(s) {', '.join(unknown) or '(none given)'} (tasks: {', '.join(runnable)}, or paper, or all)",
                                 param_hint="--tasks")
    no_graph = [t for t in task_names if t not in runnable]
    if no_graph:
        raise click.BadParameter(f"{', '.join(no_graph)} has no library graph to sweep (tasks: {', '.join(runnable)}, or paper, or all)",
                                 param_hint="--tasks")
    method_names = list(METHODS) if methods is None else _csv_list(methods)
    unknown = [m for m in method_names if m not in METHODS]
    if unknown or not method_names:
        raise click.BadParameter(f"unknown method(s) {', '.join(unknown) or '(none given)'} (methods: {', '.join(METHODS)})", param_hint="--methods")
    if ps is not None and protocol is not None:
        raise click.BadParameter("give --p or --protocol, not both", param_hint="--protocol")
    if ray_address and backend != "ray":
        raise click.BadParameter("--ray-address needs --backend ray", param_hint="--ray-address")
    conditions = [Condition(protocol=protocol)] if protocol else [Condition(p=p) for p in (ps or [0.05, 0.10])]
    if reasoner == "llm":
        from agentchord.agents.exceptions import ReasonerConfigError
        from agentchord.agents.llm import LlmConfig

        try:
            llm_config = LlmConfig.from_env()  # the settings are checked before any episode runs
        except ReasonerConfigError as error:
            raise BadInput(f"--reasoner llm: {error}") from None
        llm = {"model": llm_config.model, "endpoint": llm_config.endpoint}  # a resumed sweep must use the same
    else:
        llm = None
    config = SweepConfig(reasoning=ReasoningConfig(latency=latency, vqa_miss=vqa_miss, vqa_false_alarm=vqa_false_alarm,
                                                   doremi_every=doremi_every), reasoner=reasoner, llm=llm)
    try:
        store = RecordStore(out_dir, config)  # checks the output directory before any episode runs
    except BenchError as error:
        raise BadInput(str(error)) from None
    keys = sweep_keys(task_names, method_names, conditions, trials, first_seed)
    todo = [key for key in keys if key.id not in store]
    console = Console()
    console.print(f"[bold]bench[/bold]: {len(task_names)} task(s) x {len(method_names)} method(s) x "
                  f"{', '.join(c.label for c in conditions)} x {trials} seeds = {len(keys)} episodes; "
                  f"{len(keys) - len(todo)} already in {store.path}, {len(todo)} to run on the {backend} backend")
    console.print(describe(config))
    started = time.perf_counter()
    if todo:
        _run(todo, config, store, backend, ray_address, workers, console)
    records = [store.records[key.id] for key in keys if key.id in store.records]
    outages = [record for record in records if is_outage(record)]
    errors = [record for record in records if is_error(record) and not is_outage(record)]
    finished = [record for record in records if not is_error(record)]
    written = (write_report(finished, Path(out_dir), config, console, trials, first_seed, left_out=len(errors), outages=len(outages))
               if finished else [])
    console.print(f"{len(todo)} episode(s) in {time.perf_counter() - started:.0f} s; written: " + (", ".join(str(p) for p in written) or "nothing"))
    if errors:
        listed = "; ".join(f"{r['id']}: {r['error'][:160]}" for r in errors[:5]) + ("; ..." if len(errors) > 5 else "")
        raise EpisodesStoppedOnErrors(
            f"{len(errors)} episode(s) stopped on an internal error (a bug, not a failed task) and are left out of "
            f"every table: {listed}. Each record in {store.path} holds its traceback; rerun with the same --out "
            "to run them again.")
    if outages:
        listed = "; ".join(f"{r['id']}" for r in outages[:5]) + ("; ..." if len(outages) > 5 else "")
        raise EpisodesMetAnOutage(
            f"{len(outages)} episode(s) could not reach the LLM ({outages[0]['error'][:200]}): {listed}. They are not "
            f"results of their method and are left out of every table; rerun with the same --out when the endpoint is back.")


def _run(todo, config, store, backend, ray_address, workers, console) -> None:
    from agentchord.bench.backends import run_local, run_ray
    from agentchord.bench.exceptions import BackendError
    from agentchord.bench.sweep import is_error

    stream = run_ray(todo, config, ray_address, workers) if backend == "ray" else run_local(todo, config, workers)
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
               TextColumn("left"), TimeRemainingColumn())
    with Progress(*columns, console=console) as bar:
        job = bar.add_task("episodes", total=len(todo))
        try:
            for _key, record in stream:
                store.append(record)
                if is_error(record):
                    what = "" if record.get("outage") else "internal error: "
                    bar.console.print(f"[red]{escape(record['id'])}[/red]: {what}{escape(record['error'][:200])}", highlight=False)
                bar.advance(job)
        except BackendError as error:
            raise BadInput(str(error)) from None


def write_report(records: list[dict], out: Path, config, console: Console | None, trials: int, first_seed: int,
                 left_out: int = 0, outages: int = 0) -> list[Path]:
    """Tables (Markdown and CSV) and figures (PNG) of a sweep's records, written atomically under ``out``.

    ``left_out`` episodes stopped on an internal error and ``outages`` could not reach their LLM; the caption
    says so (the cells have fewer seeds).
    """
    from agentchord.bench.figures import steps_figure, stress_figure
    from agentchord.bench.paired import REFERENCE, paired_csv, paired_markdown
    from agentchord.bench.sweep import describe
    from agentchord.bench.tables import ABLATION_METHODS, summary_csv, table_layout, table_markdown
    from agentchord.guard.outputs import atomic_write_bytes, atomic_write_text

    written: list[Path] = []

    def write(path: Path, data: str | bytes) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        (atomic_write_text if isinstance(data, str) else atomic_write_bytes)(path, data)
        written.append(path)

    caption = (f"{trials} seeds per cell (from {first_seed}); success % [95% Wilson CI]; execution time = robot + compute + "
               f"reasoning latency, mean ± 95% t-interval half-width over successful episodes; steps = control ticks, "
               f"mean over successful episodes with a disturbance. {describe(config)}.")
    if left_out:
        caption += f" {left_out} episode(s) that stopped on an internal error are left out (see records.jsonl)."
    if outages:
        caption += f" {outages} episode(s) that could not reach the LLM are left out (see records.jsonl)."
    drops = [r for r in records if r["protocol"] is None]
    protocols = [r for r in records if r["protocol"] is not None]
    tables: list[tuple[str, str, list[dict], dict]] = []
    if drops:
        tables.append(("table1", "Table I: random drops", drops, {}))
    if protocols:
        protocol = protocols[0]["protocol"]
        title = "Table II: real-world protocol" if protocol == "real" else f"The {protocol} protocol"
        tables.append(("table2", title, protocols,
                       {"with_steps": False, "with_condition": False}))
        if {r["method"] for r in protocols} >= set(ABLATION_METHODS):
            tables.append(("table5", "Table V: forward-moving recovery vs backtracking", protocols,
                           {"methods": list(ABLATION_METHODS), "with_steps": False, "with_condition": False}))
    for name, title, rows, options in tables:
        markdown = table_markdown(rows, title, caption, **options)
        write(out / "tables" / f"{name}.md", markdown)
        header, body = table_layout(rows, **options)
        write(out / "tables" / f"{name}.csv", _csv([header, *body]))
        if console is not None:
            console.print(markdown, markup=False, highlight=False)
    write(out / "tables" / "summary.csv", summary_csv(records))
    methods = {r["method"] for r in records}
    if REFERENCE in methods and len(methods) > 1:
        # AgentChord against each method, episode by episode (pairs match task, condition and seed).
        paired = paired_markdown(records)
        write(out / "tables" / "paired.md", paired)
        write(out / "tables" / "paired.csv", paired_csv(records))
        if console is not None:
            console.print(paired, markup=False, highlight=False)
    from agentchord.bench.pipeline import decomposition_markdown, early_failures_markdown

    timing = decomposition_markdown(records) + "\n" + early_failures_markdown(records)
    write(out / "tables" / "timing.md", timing)
    if console is not None:
        console.print(timing, markup=False, highlight=False)
    if config.reasoner == "rules" and len(methods) > 1:
        # Modelled latencies only: a measured LLM call has no price to scale.
        from agentchord.bench.latency import latency_csv, latency_markdown

        plan_s = config.reasoning.latency.reference_plan_s
        sensitivity = latency_markdown(records, plan_s, describe(config) + ".")
        write(out / "tables" / "latency.md", sensitivity)
        write(out / "tables" / "latency.csv", latency_csv(records, plan_s))
        if console is not None:
            console.print(sensitivity, markup=False, highlight=False)
    figure = stress_figure(records)
    if figure is not None:
        write(out / "figures" / "stress.png", figure)
    figure = steps_figure(records)
    if figure is not None:
        write(out / "figures" / "steps.png", figure)
    return written


def _csv(rows: list[list[str]]) -> str:
    import csv
    import io

    buffer = io.StringIO()
    csv.writer(buffer).writerows(rows)
    return buffer.getvalue()
