"""``workbench grade``: every student's VIPLE program in a folder on an exercise's mazes and
seeds, in parallel, into one table."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

from workbench.files.atomic import write_text_atomic
from workbench.files.bundled import maze_path
from workbench.labs.model import Exercise, Lab, LabFileError, load_lab, load_labs
from workbench.program.grade_table import csv_text, json_text, skipped_lines, summary
from workbench.program.grading import (
    DEFAULT_DEADLINE,
    DEFAULT_MEMORY,
    Limits,
    Plan,
    Submission,
    grade,
)
from workbench.program.keys import KeyScriptError
from workbench.program.submissions import PROGRAM_FILES, FolderError, scan_folder

from . import picture as picture_cmd
from .common import report_ms_option
from .run import _simulation_options, common_keys, key_options

NAME = "workbench grade"
OUT_FORMATS = (".csv", ".json")
#: the most seeds and the smallest memory cap the command takes
MAX_SEEDS = 100
MIN_MEMORY = 256


class GradeUsageError(ValueError):
    """The command's options cannot be used together or name what is not there."""


def register(sub: argparse._SubParsersAction) -> None:
    g = sub.add_parser(
        "grade",
        help="grade a folder of students' VIPLE programs on an exercise's mazes into a table",
        description="Run every student's VIPLE program in FOLDER (NAME.viple or NAME.xml "
        "files, or one subfolder per student holding one) on the exercise's mazes and seeds, "
        "each program in a process of its own, and write one table: a row per program, maze "
        "and seed. A program that does not load, crashes, hangs or runs out of memory gets "
        "the reason in its rows; the others are graded as usual. Every file of FOLDER that is "
        "not graded is listed with the reason.",
    )
    g.add_argument("folder", metavar="FOLDER", help="the folder of the students' programs")
    g.add_argument("--lab", metavar="L", help="a bundled lab's id, or a lab file (.yaml)")
    g.add_argument("--exercise", metavar="E", help="the exercise of --lab to grade")
    g.add_argument(
        "--maze", nargs="+", default=[], metavar="M", help="without --lab: the mazes to grade on"
    )
    g.add_argument(
        "--seeds",
        type=int,
        metavar="N",
        help="seeds 0..N-1 on each maze (default: the exercise's, else 1)",
    )
    _simulation_options(g)
    report_ms_option(g)
    g.add_argument(
        "--sensor",
        action="append",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="without --lab: the robot's sensors (default: the profile's)",
    )
    g.add_argument(
        "--max-time",
        type=float,
        metavar="S",
        help="simulated seconds per run (default: the exercise's, else from the maze's size)",
    )
    key_options(g)
    g.add_argument("--kinds", metavar="MAP.yaml", help="names for unknown activity kinds")
    g.add_argument(
        "--jobs",
        type=int,
        default=os.cpu_count() or 1,
        metavar="N",
        help="programs run at once (default: the number of processors)",
    )
    g.add_argument(
        "--deadline",
        type=float,
        default=DEFAULT_DEADLINE,
        metavar="S",
        help=f"wall-clock seconds for all of one program's runs (default {DEFAULT_DEADLINE:g})",
    )
    g.add_argument(
        "--memory",
        type=int,
        default=DEFAULT_MEMORY,
        metavar="MIB",
        help="address space one program's process may map beyond the grader's, in MiB "
        f"(default {DEFAULT_MEMORY})",
    )
    g.add_argument(
        "--out",
        action="append",
        default=[],
        metavar="FILE",
        help="write the table to FILE.csv or FILE.json (may be given twice; default: CSV on "
        "standard output)",
    )
    picture_cmd.picture_option(
        g,
        "each maze's runs with seed 0 side by side, one picture per maze (FILE-MAZE.EXT beside "
        "FILE with several mazes; FILE-MAZE-2.EXT and on for more than 12 programs)",
    )
    g.set_defaults(func=cmd_grade)


def cmd_grade(args: argparse.Namespace) -> int:
    try:
        plan, what, keys = _plan(args)
        limits = _limits(args)
        for out in args.out:
            if Path(out).suffix.lower() not in OUT_FORMATS:
                raise GradeUsageError(f"--out {out}: name a .csv or a .json file")
        handins = scan_folder(args.folder, keys)
    except (GradeUsageError, FolderError, KeyScriptError) as exc:
        print(f"{NAME}: {exc}", file=sys.stderr)
        return 2
    submissions, skipped = handins.submissions, handins.skipped
    if not submissions:
        lines = [
            f"{NAME}: {args.folder} holds no programs (NAME{PROGRAM_FILES} files, or one "
            "subfolder per student holding one)",
            *skipped_lines(skipped),
        ]
        print("\n".join(lines), file=sys.stderr)
        return 2
    if picture_cmd.refused(args.picture, NAME):
        return 2
    with contextlib.ExitStack() as stack:
        if args.picture:
            records = stack.enter_context(tempfile.TemporaryDirectory(prefix="workbench-grade-"))
            for no in range(len(plan.mazes)):
                os.mkdir(os.path.join(records, f"{no + 1:02d}"))
            plan = dataclasses.replace(plan, records=records)
        code = _graded(args, plan, what, submissions, skipped, limits)
        if args.picture and code == 0:
            code = grade_pictures(args.picture, plan, submissions)
        return code


def grade_pictures(target: str, plan: Plan, submissions: list[Submission]) -> int:
    """One picture per maze of the programs' seed-0 runs side by side (in groups of 12); a
    record that cannot be drawn (a program that did not run, a record its program made too
    large) is left out and said."""
    from workbench.pictures.render import PictureSpec, save_picture
    from workbench.pictures.runs import MAX_RUNS, PictureError, load_run

    worst = 0
    for no, path in enumerate(picture_cmd.maze_pictures(target, list(plan.mazes))):
        runs = []
        for index, submission in enumerate(submissions):
            record = plan.record_of(no, index, submission)
            if record is None or not os.path.isfile(record):
                continue
            try:
                runs.append(load_run(record))
            except PictureError as exc:
                print(
                    f"{NAME}: picture: {submission.student}'s run left out: {exc}", file=sys.stderr
                )
        groups = [runs[i : i + MAX_RUNS] for i in range(0, len(runs), MAX_RUNS)]
        for part, group in enumerate(groups, start=1):
            name = path if part == 1 else path.with_name(f"{path.stem}-{part}{path.suffix}")
            try:
                written = save_picture(group, name, PictureSpec("compare"))
            except PictureError as exc:
                print(f"{NAME}: {exc}", file=sys.stderr)
                worst = 2
                continue
            print(picture_cmd.said(written, "compare"), file=sys.stderr)
        if not groups:
            print(f"{NAME}: picture: no run on {plan.mazes[no]} to draw", file=sys.stderr)
    return worst


def _graded(
    args: argparse.Namespace,
    plan: Plan,
    what: dict[str, str],
    submissions: list[Submission],
    skipped: list,
    limits: Limits,
) -> int:
    """Grade, write the table, say the summary; the exit code."""
    shown = sys.stderr.isatty()
    started = time.monotonic()
    rows = grade(
        submissions, plan, jobs=args.jobs, limits=limits, progress=_progress if shown else None
    )
    if shown:
        sys.stderr.write("\r\x1b[K")
    for out in args.out:
        as_csv = Path(out).suffix.lower() == ".csv"
        text = csv_text(rows) if as_csv else json_text(rows, plan, what, skipped)
        try:
            write_text_atomic(out, text)
        except OSError as exc:
            print(f"{NAME}: {out}: cannot write the table: {exc.strerror}", file=sys.stderr)
            return 2
    if not args.out:
        sys.stdout.write(csv_text(rows))
        sys.stdout.flush()
    lines = summary(rows)
    lines[0] += f" ({time.monotonic() - started:.1f} s)"
    lines += skipped_lines(skipped)
    print("\n".join(lines), file=sys.stderr)
    return 0


def _plan(args: argparse.Namespace) -> tuple[Plan, dict[str, str], str]:
    """What every program runs on, what is graded (for the JSON table) and the key script."""
    if args.seeds is not None and not 1 <= args.seeds <= MAX_SEEDS:
        raise GradeUsageError(f"--seeds must be from 1 to {MAX_SEEDS}")
    if args.max_time is not None and not 0 < args.max_time <= 24 * 3600:
        raise GradeUsageError("--max-time must be above 0 and at most a day")
    if not os.path.isdir(args.folder):
        raise GradeUsageError(f"{args.folder}: no such folder (give the folder of programs)")
    folder = os.path.abspath(args.folder)
    keys = common_keys(args)
    kinds = os.path.abspath(args.kinds) if args.kinds else None
    common = {
        "folder": folder,
        "noise": args.noise,
        "noise_params": tuple(args.noise_set),
        "kinds": kinds,
        "report_ms": args.report_ms,
    }
    if args.lab or args.exercise:
        if not (args.lab and args.exercise):
            raise GradeUsageError("give --lab L and --exercise E together")
        for given, option in ((args.maze, "--maze"), (args.sensor, "--sensor"),
                              (args.profile, "--profile")):  # fmt: skip
            if given:
                raise GradeUsageError(f"{option} is the exercise's to say: drop it with --lab")
        lab = _lab(args.lab)
        exercise = _exercise(lab, args.exercise)
        graded = exercise.graded
        plan = Plan(
            mazes=tuple(str(m.path) for m in graded.mazes),
            seeds=args.seeds or graded.seeds,
            profile=exercise.setup.profile,
            sensors=tuple(str(s) for s in exercise.setup.sensors),
            max_time=args.max_time or graded.max_time,
            **common,
        )
        return plan, {"lab": lab.id, "exercise": exercise.id}, keys
    if not args.maze:
        raise GradeUsageError("give --lab L --exercise E, or the mazes with --maze M ...")
    mazes = [maze_path(m) for m in args.maze]
    for typed, maze in zip(args.maze, mazes, strict=True):
        if not os.path.isfile(maze):
            raise GradeUsageError(f"--maze {typed}: no such file, nor a bundled maze's name")
    plan = Plan(
        mazes=tuple(os.path.abspath(m) for m in mazes),
        seeds=args.seeds or 1,
        profile=args.profile,
        sensors=tuple(args.sensor),
        max_time=args.max_time,
        **common,
    )
    return plan, {}, keys


def _limits(args: argparse.Namespace) -> Limits:
    if args.jobs < 1:
        raise GradeUsageError("--jobs must be at least 1")
    if not 0 < args.deadline <= 24 * 3600:
        raise GradeUsageError("--deadline must be above 0 and at most a day (seconds)")
    if args.memory < MIN_MEMORY:
        raise GradeUsageError(f"--memory must be at least {MIN_MEMORY} (MiB)")
    return Limits(deadline=args.deadline, memory=args.memory)


def _lab(name: str) -> Lab:
    try:
        if name.endswith(".yaml"):
            return load_lab(name)
        labs = load_labs()
    except LabFileError as exc:
        raise GradeUsageError(str(exc)) from None
    for lab in labs:
        if lab.id == name:
            return lab
    known = ", ".join(lab.id for lab in labs)
    raise GradeUsageError(f"--lab {name}: no such lab (the bundled ones: {known}; or a .yaml file)")


def _exercise(lab: Lab, exercise_id: str) -> Exercise:
    try:
        return lab.exercise(exercise_id)
    except KeyError as exc:
        raise GradeUsageError(str(exc.args[0])) from None


def _progress(done: int, total: int, submission: Submission) -> None:
    line = f"graded {done} of {total}: {submission.file}"
    sys.stderr.write("\r\x1b[K" + line[:100])
    sys.stderr.flush()
