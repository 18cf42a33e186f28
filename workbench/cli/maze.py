"""``workbench maze ...``: check, show, convert and generate mazes."""

from __future__ import annotations

import argparse
import json
import sys

from workbench.sim.generate import EXITS, STYLES, check_seed, check_size, generate
from workbench.sim.maze import Maze, MazeError, Problem, cap_problems, problem_fields
from workbench.sim.mazefile import format_maze, write_maze
from workbench.sim.mazeio import format_for_path, load_maze, save_maze
from workbench.sim.mazeview import render


def register(sub: argparse._SubParsersAction) -> None:
    maze = sub.add_parser("maze", help="check, show, convert and generate mazes")
    msub = maze.add_subparsers(dest="maze_command", metavar="ACTION", required=True)

    check = msub.add_parser("check", help="validate maze files (exit 0 when all are valid)")
    check.add_argument("files", nargs="+", metavar="FILE")
    check.add_argument("--json", action="store_true", help="one JSON object per line")
    check.add_argument("--from", dest="fmt", help="force the input format")
    check.set_defaults(func=cmd_check)

    show = msub.add_parser("show", help="draw a maze")
    show.add_argument("file", metavar="FILE")
    show.add_argument("--unicode", action="store_true", help="box-drawing characters")
    show.add_argument("--from", dest="fmt", help="force the input format")
    show.set_defaults(func=cmd_show)

    gen = msub.add_parser(
        "generate", help="generate a random maze from a seed (the same seed, the same maze)"
    )
    gen.add_argument(
        "--size",
        required=True,
        type=parse_size,
        metavar="WxH",
        help="size in cells, e.g. 16x16 (1 to 99 each way; a cell and its walls are 2 blocks)",
    )
    gen.add_argument("--seed", required=True, type=parse_seed, help="a whole number, 0 or more")
    gen.add_argument("--style", choices=STYLES, default="perfect", help="default: perfect")
    gen.add_argument(
        "--exit",
        dest="exit_option",
        choices=EXITS,
        default="boundary",
        help="an opening in the outer wall (default), the centre cells, or none",
    )
    gen.add_argument("-o", "--output", metavar="FILE", help="write here instead of stdout")
    gen.set_defaults(func=cmd_generate)

    convert = msub.add_parser(
        "convert", help="convert a maze file (writes nothing when the input is invalid)"
    )
    convert.add_argument("input", metavar="IN")
    convert.add_argument("output", metavar="OUT")
    convert.add_argument("--from", dest="fmt", help="force the input format")
    convert.add_argument(
        "--to",
        dest="to_fmt",
        help="workbench, micromouse or maz (default: maz for a .maz OUT, else workbench)",
    )
    convert.set_defaults(func=cmd_convert)


def check_report(maze: Maze | None, problems: list[Problem], source: str) -> dict:
    report: dict = {"file": source, "valid": not problems}
    if maze is not None:
        report.update(
            name=maze.name,
            width=maze.width,
            height=maze.height,
            start=list(maze.start) if maze.start else None,
            heading=maze.heading,
            exits=[list(e) for e in maze.exits],
            shortest_path=maze.shortest_path_length() if not problems else None,
            notes=maze.notes() if not problems else [],
        )
    report["problems"] = [problem_fields(p) for p in problems]
    return report


def check_one(path: str, fmt: str | None = None) -> tuple[Maze | None, list[Problem]]:
    try:
        maze = load_maze(path, fmt)
    except MazeError as exc:
        return None, exc.problems
    return maze, cap_problems(maze.validate())


def describe(report: dict) -> str:
    if "width" not in report:
        return f"{report['file']}: INVALID"
    start = report["start"]
    start_txt = f"({start[0]}, {start[1]}) facing {report['heading']}" if start else "none"
    exits = report["exits"]
    exits_txt = ", ".join(f"({x}, {y})" for x, y in exits) if exits else "none"
    sp = report["shortest_path"]
    lines = [
        f"{report['file']}: {'valid' if report['valid'] else 'INVALID'}"
        + (f" - {report['name']}" if report["name"] else ""),
        f"  size {report['width']}x{report['height']} blocks, start {start_txt}",
        f"  exits {exits_txt}",
    ]
    if report["valid"] and exits:
        lines.append(f"  shortest path to an exit: {sp} blocks")
    lines += [f"  note: {n}" for n in report["notes"]]
    return "\n".join(lines)


def cmd_check(args: argparse.Namespace) -> int:
    ok = True
    for path in args.files:
        maze, problems = check_one(path, args.fmt)
        report = check_report(maze, problems, path)
        ok &= report["valid"]
        if args.json:
            print(json.dumps(report, sort_keys=True))
        else:
            print(describe(report))
            for p in problems:
                print(f"  {p}")
    return 0 if ok else 1


def cmd_show(args: argparse.Namespace) -> int:
    try:
        maze = load_maze(args.file, args.fmt)
    except MazeError as exc:
        for p in exc.problems:
            print(p, file=sys.stderr)
        return 1
    print(render(maze, unicode=args.unicode))
    return 0


def cmd_convert(args: argparse.Namespace) -> int:
    maze, problems = check_one(args.input, args.fmt)
    if maze is None or problems:
        for p in problems:
            print(p, file=sys.stderr)
        print(f"{args.output}: not written, {args.input} is not a valid maze", file=sys.stderr)
        return 1
    fmt = args.to_fmt or format_for_path(args.output)
    try:
        save_maze(args.output, maze, fmt)
    except MazeError as exc:
        for p in exc.problems:
            print(p, file=sys.stderr)
        print(f"{args.output}: not written, the maze cannot be saved as {fmt}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"{args.output}: cannot write: {exc.strerror} (check the path)", file=sys.stderr)
        return 1
    print(f"{args.output}: written as {fmt}, {maze.width}x{maze.height} blocks")
    back = load_maze(args.output)
    if back.heading != maze.heading:
        print(
            f"note: {fmt} has no start heading; {args.output} starts facing {back.heading}, "
            f"not {maze.heading}"
        )
    return 0


def parse_seed(text: str) -> int:
    """A ``--seed`` value; argparse reports the error and exits with 2."""
    try:
        seed = int(text)
        check_seed(seed)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a seed: give a whole number 0 or more, e.g. 7"
        ) from None
    return seed


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` in cells, for ``--size``; argparse reports the error and exits with 2."""
    parts = [p.strip() for p in text.strip().lower().split("x")]
    if len(parts) != 2 or not all(p.isascii() and p.isdigit() for p in parts):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a size: give WIDTHxHEIGHT in cells, e.g. 16x16"
        )
    width, height = int(parts[0]), int(parts[1])
    try:
        check_size(width, height)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return width, height


def cmd_generate(args: argparse.Namespace) -> int:
    width, height = args.size
    maze = generate(width, height, args.seed, args.style, args.exit_option)
    if args.output is None:
        print(format_maze(maze), end="")
        return 0
    try:
        write_maze(args.output, maze)
    except OSError as exc:
        print(f"{args.output}: cannot write: {exc.strerror} (check the path)", file=sys.stderr)
        return 1
    print(f"{args.output}: written, {maze.name} ({maze.width}x{maze.height} blocks)")
    return 0


def show_and_check(path: str) -> int:
    maze, problems = check_one(path)
    if maze is not None:
        print(render(maze))
        print()
    report = check_report(maze, problems, path)
    print(describe(report))
    for p in problems:
        print(f"  {p}")
    return 0 if report["valid"] else 1
