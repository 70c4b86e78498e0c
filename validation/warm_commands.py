"""Whole commands cold and served by a warm process, paired, on the built-in scenes.

Each command runs as a user runs it (``python -m rt70 …`` as a subprocess, no plot),
once in its own interpreter (``RT70_WARM=0``: start-up included) and once served by a
warm process of the script's own (``rt70 warm start`` on a temporary socket), in turn,
``--repeats`` times; the best wall time of each counts. The commands: the RT-70's 10 s
transient, the four servo scenarios of rt70_servo, its modes, its plant and its wind
pointing budget. The warm process's start (its warm-up) is timed too.

Run: ``python validation/warm_commands.py`` (about a minute). Writes
validation/results/warm_commands.md.
"""

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from rt70.guards.atomic import atomic_write_text
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.targets import wall_times, warm_process

OUT = Path(__file__).resolve().parent / "results" / "warm_commands.md"
#: Each command's words after ``rt70``, and the time it simulates (s; None: not a run).
COMMANDS = (
    (["simulate", "rt70", "--t-end", "10", "--no-plot"], 10.0),
    (["simulate", "rt70_servo", "--scenario", "hold", "--no-plot"], 60.0),
    (["simulate", "rt70_servo", "--scenario", "track", "--no-plot"], 40.0),
    (["simulate", "rt70_servo", "--scenario", "step-elevation", "--no-plot"], 25.0),
    (["simulate", "rt70_servo", "--scenario", "step-azimuth", "--no-plot"], 40.0),
    (["modes", "rt70_servo"], None),
    (["plant", "rt70_servo"], None),
    (["pointing", "rt70_servo", "--wind", "10"], None),
)


def row(words: list[str], simulated: float | None, repeats: int, warm: dict) -> str:
    """One table row: the best cold and warm wall times, their ratio, × real time."""
    cold, hot = [], []
    for _ in range(repeats):
        cold += wall_times(words, 1)
        hot += wall_times(words, 1, warm)
    speed = ""
    if simulated is not None:
        speed = f"{simulated / min(cold):.1f}× → {simulated / min(hot):.1f}×"
    return (
        f"| `rt70 {' '.join(words)}` | {min(cold):.2f} s | {min(hot):.2f} s | "
        f"{min(cold) / min(hot):.1f} | {speed} |"
    )


def warm_up_seconds() -> float:
    """Wall time of ``rt70 warm start`` (its warm-up) on a socket of its own, s."""
    directory = Path(os.environ.get("TMPDIR", "/tmp"))
    env = {**os.environ, "RT70_WARM_SOCKET": str(directory / f"rt70w-{os.getpid()}.sock")}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rt70", "warm", "start"], env=env, check=True,
                   capture_output=True)  # fmt: skip
    seconds = time.perf_counter() - start
    subprocess.run([sys.executable, "-m", "rt70", "warm", "stop"], env=env, capture_output=True)
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs of each (best counts)")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    start_s = warm_up_seconds()
    table = []
    with warm_process() as warm:
        for words, simulated in COMMANDS:
            table.append(row(words, simulated, args.repeats, warm))
            print(table[-1], flush=True)
    text = "\n".join(
        [
            "# Whole commands, cold and served by a warm process",
            "",
            f"Wall time of each command as a subprocess, best of {args.repeats}, cold "
            "(`RT70_WARM=0`, its own interpreter) and warm (`rt70 warm start` running) in "
            f"turn. `rt70 warm start` itself (the warm-up): {start_s:.2f} s. "
            "docs/performance.md, 'The warm process', discusses them.",
            "",
            "| command | cold | warm | cold / warm | × real time, cold → warm |",
            "|---|---:|---:|---:|---|",
            *table,
            "",
        ]
    )
    atomic_write_text(OUT, headed(text, run_header(command_line())))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
