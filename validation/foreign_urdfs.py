"""Every URDF file of pybullet_data through rt70: agree / refused (kind) / disagree / crashed.

Run: ``python validation/foreign_urdfs.py [--jobs N] [--samples N] [OUT_DIR]`` (pybullet is
a test dependency: ``pip install -e '.[test]'``). Writes ``foreign_urdfs.md`` and
``foreign_urdfs.csv`` to ``OUT_DIR`` (default ``validation/results``).

Each file is read as rt70 reads a scene (:func:`rt70.model.scene.load_scene`), both sides are
built and :func:`rt70.crosscheck.validate.cross_check` compares them on a few random states, once
as is and once with ``balance_inertia=True``. A file is

- **agree**: every quantity within :data:`rt70.crosscheck.validate.DEFAULT_TOLERANCE`;
- **refused**: an :class:`rt70.errors.Rt70Error`, tabulated by kind (:data:`KINDS`); a
  model with no degree of freedom is its own kind (nothing to cross-check);
- **disagree**: some quantity beyond the tolerance;
- **crashed**: any other exception, a signal (Pinocchio's C++ can segfault on hostile
  input) or the time limit — a bug in rt70 either way.

Each classification runs in its own forked process (:func:`isolated`), so neither a
Python exception nor a segfault in one file stops the run. Measured on the 2-core
machine shared with other jobs (load average 3–4), both passes over the 1095 files:
5 s in one process without isolation, 19–21 s forked with ``--jobs 1``, 25–36 s with
``--jobs 2`` — the cost is the kernel's work of forking (about 8 ms a file), which a
second worker does not share out; hence the default of one. For a refused file the
report says whether Pinocchio's parser alone loads the raw text (does rt70 refuse what
another reader takes?).
"""

from __future__ import annotations

import argparse
import csv
import io
import multiprocessing
import multiprocessing.connection
import os
import sys
import time
import traceback
import warnings
from collections import Counter
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

from rt70 import errors
from rt70.crosscheck.validate import DEFAULT_TOLERANCE, cross_check
from rt70.guards.atomic import atomic_write_text
from rt70.model.scene import load_scene
from rt70.reports.provenance import command_line, headed, run_header

OUT = Path(__file__).resolve().parent / "results"

#: Refusal kinds, most specific first: the first class the error is an instance of wins.
KINDS: tuple[tuple[type[errors.Rt70Error], str], ...] = (
    (errors.XacroError, "xacro file"),
    (errors.DtdError, "DTD entity"),
    (errors.MasslessCoordinateError, "coordinate moves no mass"),
    (errors.MagnitudeError, "huge value"),
    (errors.NonFiniteError, "NaN or infinite value"),
    (errors.InertiaError, "impossible inertia"),
    (errors.JointTypeError, "unsupported joint type"),
    (errors.TopologyError, "broken kinematic tree"),
    (errors.ExtensionError, "bad rt70 extension"),
    (errors.UrdfError, "malformed URDF"),
)
#: The kind of a model with no degree of freedom.
NO_DOF = "no degree of freedom"
#: Every kind a refusal may have; anything else is reported as unexpected.
KNOWN_KINDS = (*(kind for _, kind in KINDS), NO_DOF)

#: Warning kinds: a substring of the message, and the kind.
WARNING_KINDS = (
    ("ignored, the link is", "ground inertia ignored"),
    ("is added to the rigid body", "zero-mass inertia merged"),
    ("whitespace before the XML declaration", "whitespace before <?xml"),
    ("NUL characters after the document", "NUL after the document"),
    ("inertia repaired (balance inertia", "inertia balanced"),
    ("Pinocchio's URDF parser:", "Pinocchio parser message"),
    ("is not URDF, ignored", "unknown URDF attribute"),
)

CATEGORIES = ("agree", "refused", "disagree", "crashed")

#: Files of one directory with one outcome are one row of the markdown table above this.
GROUP_ABOVE = 50

#: Wall-time limit of one classification, s (a hang is a crash).
TIME_LIMIT_S = 300.0


def refusal_kind(exc: errors.Rt70Error) -> str:
    """The kind of a refusal (:data:`KINDS`); ``"unexpected <Type>"`` if none fits."""
    for cls, kind in KINDS:
        if isinstance(exc, cls):
            return kind
    return f"unexpected {type(exc).__name__}"


def warning_kind(message: str) -> str:
    """The kind of an :class:`rt70.errors.Rt70Warning` message (:data:`WARNING_KINDS`)."""
    for needle, kind in WARNING_KINDS:
        if needle in message:
            return kind
    return "other"


@dataclass
class Outcome:
    """What rt70 made of one file."""

    file: str
    category: str = "crashed"
    kind: str = ""  # refusal kind, or the worst quantity of a disagreement
    detail: str = ""  # the one-line message (path removed)
    nv: int | None = None
    max_rel_err: float | None = None
    max_abs_err: float | None = None
    warnings: list[str] = field(default_factory=list)
    pinocchio_loads: bool | None = None  # raw text, Pinocchio alone (refused files only)
    seconds: float = 0.0


def _one_line(text: str, path: Path) -> str:
    text = " ".join(str(text).split())
    return text.replace(f"{path}: ", "").replace(str(path), "FILE")


def classify(
    path: Path, samples: int = 3, balance_inertia: bool = False, label: str | None = None
) -> Outcome:
    """Classify one URDF file (in this process; :func:`isolated` runs it in a child)."""
    out = Outcome(label or str(path))
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", errors.Rt70Warning)
        try:
            scene = load_scene(path, balance_inertia=balance_inertia)
            out.nv = scene.textbook.nv
            if out.nv == 0:
                out.category, out.kind = "refused", NO_DOF
                out.detail = "the model has no degree of freedom: nothing to cross-check"
            else:
                records = cross_check(scene, samples=samples, seed=0, repeat=0)
                worst = max(records, key=lambda r: r.max_rel_err)
                out.max_rel_err = float(worst.max_rel_err)
                ok = all(r.passed(DEFAULT_TOLERANCE) for r in records)
                out.category = "agree" if ok else "disagree"
                out.kind = "" if ok else worst.quantity
                out.max_abs_err = float(worst.max_abs_err)
                out.detail = (
                    f"worst {worst.quantity}: rel {worst.max_rel_err:.2e}, "
                    f"abs {worst.max_abs_err:.2e}"
                )
        except errors.Rt70Error as exc:
            out.category, out.kind, out.detail = "refused", refusal_kind(exc), _one_line(exc, path)
        except Exception as exc:  # a bug in rt70: reported, never dropped
            out.category, out.kind = "crashed", type(exc).__name__
            frame = traceback.extract_tb(exc.__traceback__)[-1]
            where = f"{Path(frame.filename).name}:{frame.lineno}"
            out.detail = _one_line(f"{type(exc).__name__}: {exc} (at {where})", path)
    out.warnings = sorted(
        {warning_kind(str(w.message)) for w in caught if issubclass(w.category, errors.Rt70Warning)}
    )
    if out.category == "refused":
        out.pinocchio_loads = _pinocchio_loads(path)
    out.seconds = time.perf_counter() - start
    return out


def _pinocchio_loads(path: Path) -> bool:
    """Whether Pinocchio's URDF parser alone builds a model from the raw file."""
    import pinocchio as pin

    try:
        pin.buildModelFromXML(path.read_text(encoding="utf-8", errors="replace"))
    except Exception:
        return False
    return True


def _child(conn, path: Path, samples: int, balance: bool, label: str) -> None:
    """Body of the forked child: silence C++ stderr chatter, classify, send, exit."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        conn.send(classify(path, samples, balance, label))
    finally:
        conn.close()
        os._exit(0)


def isolated(
    jobs_in: list[tuple[Path, str, bool]], samples: int, jobs: int, progress=None
) -> list[Outcome]:
    """Classify each ``(path, label, balance)`` in its own forked child, ``jobs`` at once.

    A child that dies (a signal, e.g. a segfault in Pinocchio) or outlives
    :data:`TIME_LIMIT_S` is recorded as crashed. Forking is cheap: the parent has
    already imported numpy and Pinocchio, the child inherits them.
    """
    ctx = multiprocessing.get_context("fork")
    pending = list(enumerate(jobs_in))[::-1]
    running: dict = {}  # conn -> (index, process, start, label)
    results: list[Outcome | None] = [None] * len(jobs_in)
    done = 0
    while pending or running:
        while pending and len(running) < jobs:
            index, (path, label, balance) = pending.pop()
            parent_conn, child_conn = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_child, args=(child_conn, path, samples, balance, label))
            proc.start()
            child_conn.close()
            running[parent_conn] = (index, proc, time.perf_counter(), label)
        ready = multiprocessing.connection.wait(list(running), timeout=5.0)
        for conn in ready:
            index, proc, start, label = running.pop(conn)
            try:
                results[index] = conn.recv()
            except EOFError:
                proc.join()
                results[index] = Outcome(
                    label, "crashed", "signal", f"child died (exit code {proc.exitcode})"
                )
            conn.close()
            proc.join()
            done += 1
            if progress:
                progress(done, len(jobs_in), results[index])
        now = time.perf_counter()
        for conn, (index, proc, start, label) in list(running.items()):
            if now - start > TIME_LIMIT_S:
                proc.kill()
                proc.join()
                conn.close()
                del running[conn]
                results[index] = Outcome(label, "crashed", "timeout", f"over {TIME_LIMIT_S:g} s")
                done += 1
    return [r for r in results if r is not None]


def pybullet_files() -> tuple[Path, list[Path]]:
    """pybullet_data's directory and all its ``*.urdf`` files, sorted."""
    import pybullet_data

    root = Path(pybullet_data.getDataPath())
    return root, sorted(root.rglob("*.urdf"))


# --- the report ---------------------------------------------------------------------


def _counts(rows: list[Outcome]) -> tuple[Counter, Counter]:
    refused = Counter(r.kind for r in rows if r.category == "refused")
    return Counter(r.category for r in rows), refused


def _md_table(header: list[str], rows: list[list[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows]
    return out


def _cell(o: Outcome) -> str:
    if o.category == "refused":
        return f"refused ({o.kind})"
    if o.category in ("disagree", "crashed"):
        return f"{o.category} ({o.kind})"
    return "agree"


def _group_key(plain: Outcome, balanced: Outcome) -> tuple:
    return (_cell(plain), _cell(balanced), tuple(plain.warnings), plain.pinocchio_loads)


def write_report(
    plain: list[Outcome], balanced: list[Outcome], out_dir: Path, meta: dict
) -> list[Path]:
    """Write ``foreign_urdfs.md`` and ``foreign_urdfs.csv``; return their paths."""
    cats, kinds = _counts(plain)
    bcats, bkinds = _counts(balanced)
    lines = [
        "# pybullet_data through rt70",
        "",
        f"Generated by `python validation/foreign_urdfs.py` — {meta['files']} URDF files of "
        f"pybullet_data (pybullet {meta['pybullet']}), Pinocchio {meta['pinocchio']}, "
        f"Python {meta['python']}; {meta['samples']} random states per file, seed 0, "
        f"tolerance {DEFAULT_TOLERANCE:g}; {meta['jobs']} worker(s), each file in its own "
        f"forked process; total run time {meta['seconds']:.0f} s.",
        "",
        "Each file is read as a scene (`rt70.model.scene.load_scene`), both sides are built and "
        "`rt70.crosscheck.validate.cross_check` compares them; 'with balance' repeats it with "
        "`balance_inertia=True` (`rt70 validate --balance-inertia`). Categories and kinds: "
        "see the script's docstring and docs/urdf-reader.md. 'Pinocchio alone' says, for a "
        "refused file, whether `pinocchio.buildModelFromXML` builds a model from the raw text.",
        "",
        "## Counts",
        "",
    ]
    lines += _md_table(
        ["category", "as is", "with balance"],
        [[c, str(cats[c]), str(bcats[c])] for c in CATEGORIES]
        + [["total", str(len(plain)), str(len(balanced))]],
    )
    lines += ["", "Refusals by kind:", ""]
    all_kinds = [k for k in KNOWN_KINDS if kinds[k] or bkinds[k]]
    all_kinds += sorted((set(kinds) | set(bkinds)) - set(KNOWN_KINDS))
    pin_ok = Counter(r.kind for r in plain if r.category == "refused" and r.pinocchio_loads)
    lines += _md_table(
        ["refusal kind", "as is", "with balance", "of them (as is) Pinocchio alone loads"],
        [[k, str(kinds[k]), str(bkinds[k]), str(pin_ok[k])] for k in all_kinds],
    )
    warn_counts = Counter(w for r in plain for w in r.warnings)
    lines += ["", "Files read with a warning (as is), by warning kind:", ""]
    lines += _md_table(["warning", "files"], [[w, str(n)] for w, n in sorted(warn_counts.items())])
    more = sum(
        1
        for p, b in zip(plain, balanced, strict=True)
        if b.category == "agree" and p.category != "agree"
    )
    lines += [
        "",
        f"With `balance_inertia=True`, {more} more file(s) agree (each repair is listed "
        "as a warning by `rt70 validate --balance-inertia`).",
        "",
        "## Disagreements",
        "",
        "The scale is the absolute error over the relative one: the size of the quantity the "
        "error was measured against.",
        "",
    ]
    lines += [
        f"- `{o.file}` ({run}): {o.kind}, absolute error {o.max_abs_err:.2e}, relative "
        f"{o.max_rel_err:.2e}, scale {o.max_abs_err / o.max_rel_err:.2e}"
        for run, rows_ in (("as is", plain), ("with balance", balanced))
        for o in rows_
        if o.category == "disagree" and o.max_rel_err
    ] or ["- none"]
    lines += [
        "",
        "## Files",
        "",
        f"Files of one directory with the same outcome are grouped when there are more than "
        f"{GROUP_ABOVE} of them (the CSV lists every file).",
        "",
    ]
    groups: dict[tuple, list[int]] = {}
    for i, (p, b) in enumerate(zip(plain, balanced, strict=True)):
        key = (str(Path(p.file).parent), *_group_key(p, b))
        groups.setdefault(key, []).append(i)
    rows = []
    shown = set()
    for i, (p, b) in enumerate(zip(plain, balanced, strict=True)):
        if i in shown:
            continue
        key = (str(Path(p.file).parent), *_group_key(p, b))
        members = groups[key]
        name = f"`{p.file}`"
        if len(members) > GROUP_ABOVE:
            shown.update(members)
            name = f"`{Path(p.file).parent}/` ({len(members)} files: `{Path(p.file).name}` …)"
        pin = "" if p.pinocchio_loads is None else ("yes" if p.pinocchio_loads else "no")
        rows.append(
            [
                name,
                "" if p.nv is None else str(p.nv),
                _cell(p),
                _cell(b),
                ", ".join(p.warnings),
                pin,
                p.detail,
            ]
        )
    lines += _md_table(
        ["file", "nv", "as is", "with balance", "warnings", "Pinocchio alone", "detail (as is)"],
        rows,
    )
    page = headed("\n".join(lines), run_header(command_line()))
    md = atomic_write_text(out_dir / "foreign_urdfs.md", page + "\n")

    buf = io.StringIO()
    names = [f.name for f in fields(Outcome)]
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["run", *names])
    for run, rows_ in (("as is", plain), ("balance", balanced)):
        for o in rows_:
            d = asdict(o)
            d["warnings"] = "; ".join(o.warnings)
            d["seconds"] = f"{o.seconds:.3f}"
            writer.writerow([run, *(d[n] for n in names)])
    csv_path = atomic_write_text(out_dir / "foreign_urdfs.csv", buf.getvalue())
    return [md, csv_path]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(OUT), help="output directory")
    parser.add_argument(
        "--jobs", type=int, default=1, help="files classified at once (default 1: see docstring)"
    )
    parser.add_argument("--samples", type=int, default=3, help="random states per file")
    args = parser.parse_args(argv)
    if args.jobs < 1 or args.samples < 1:
        parser.error("--jobs and --samples must be at least 1")
    import importlib.metadata

    import pinocchio

    start = time.perf_counter()
    root, files = pybullet_files()
    labels = [str(f.relative_to(root)) for f in files]

    def progress(done: int, total: int, outcome: Outcome) -> None:
        if done % 100 == 0 or outcome.category in ("crashed", "disagree"):
            print(
                f"  [{time.perf_counter() - start:6.1f} s] {done}/{total} {outcome.file}: "
                f"{_cell(outcome)}",
                file=sys.stderr,
                flush=True,
            )

    work = [(f, lab, False) for f, lab in zip(files, labels, strict=True)]
    work += [(f, lab, True) for f, lab in zip(files, labels, strict=True)]
    results = isolated(work, args.samples, args.jobs, progress)
    plain, balanced = results[: len(files)], results[len(files) :]
    seconds = time.perf_counter() - start
    meta = {
        "files": len(files),
        "pybullet": importlib.metadata.version("pybullet"),
        "pinocchio": pinocchio.__version__,
        "python": sys.version.split()[0],
        "samples": args.samples,
        "jobs": args.jobs,
        "seconds": seconds,
    }
    for path in write_report(plain, balanced, Path(args.out), meta):
        print(f"wrote {path}")
    for title, rows in (("as is", plain), ("with balance", balanced)):
        cats, kinds = _counts(rows)
        print(f"{title}: " + ", ".join(f"{c} {cats[c]}" for c in CATEGORIES))
        for kind, n in sorted(kinds.items(), key=lambda kv: -kv[1]):
            print(f"  refused ({kind}): {n}")
    print(f"total run time {seconds:.1f} s ({args.jobs} worker(s))")
    bad = [r for r in results if r.category in ("crashed", "disagree")]
    bad += [r for r in results if r.category == "refused" and r.kind not in KNOWN_KINDS]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
