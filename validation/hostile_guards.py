"""Hostile invocations of every rt70 command but ``sweep``, each run and classified.

Issue 21 §3 (resource and magnitude guards). Each case runs ``python -m rt70 ...`` in
its own process with a time limit and an address-space limit, and is classified:

``clean``
    exit 0 with no stray warning and no NaN/inf in the output, or exit 2 with exactly
    one stderr line starting ``rt70: error:``;
``traceback``
    a Python traceback on stderr;
``hang``
    no exit within the time limit;
``warning``
    a numpy/scipy warning (``...Warning:``) on stderr;
``nan``
    ``nan`` or ``inf`` printed on stdout;
``unclear``
    anything else (exit 2 with several lines, exit 1, a crash by signal).

Usage::

    python validation/hostile_guards.py [--timeout 60] [--only SUBSTRING] [--jobs 1]

It prints one line per case and a count per class; the exit status is 0 when every case
is clean. The scenes it changes are written to a temporary directory.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SERVO = ROOT / "urdf" / "rt70_servo.urdf"

#: Address-space limit of each case, bytes: a run that would exhaust the machine fails
#: with MemoryError (a traceback) instead.
ADDRESS_SPACE = 8 * 2**30

NAN = re.compile(r"(?<![\w.])-?(nan|inf|infinity)(?![\w])", re.IGNORECASE)
WARNING = re.compile(r"\w*Warning\b")


@dataclass
class Case:
    name: str
    argv: list[str]


def _servo_variant(tmp: Path, name: str, old: str, new: str) -> str:
    text = SERVO.read_text()
    assert old in text, old
    path = tmp / f"{name}.urdf"
    path.write_text(text.replace(old, new, 1))
    return str(path)


def _table_scene(tmp: Path, name: str, table: str) -> str:
    """rt70_servo with its main-mirror wind reading ``coefficients=table``."""
    return _servo_variant(
        tmp,
        name,
        'name="main_mirror" link="main_mirror" shape="dish"',
        f'name="main_mirror" link="main_mirror" coefficients="{table}"',
    )


def _drive(tmp: Path, name: str, key: str, value: str, axis: str = "elevation") -> str:
    text = SERVO.read_text()
    line = next(x for x in text.splitlines() if f'<rt70:drive name="{axis}"' in x)
    new = re.sub(rf' {key}="[^"]*"', f' {key}="{value}"', line)
    path = tmp / f"{name}.urdf"
    path.write_text(text.replace(line, new))
    return str(path)


def cases(tmp: Path) -> list[Case]:
    """The battery: about 100 hostile invocations."""
    c: list[Case] = []
    add = lambda name, *argv: c.append(Case(name, list(argv)))  # noqa: E731

    # coefficient tables: special files, huge values, huge files
    fifo = tmp / "fifo.csv"
    os.mkfifo(fifo)
    (tmp / "dir.csv").mkdir()
    header = "theta_deg,axial,normal,moment\n"
    (tmp / "big.csv").write_text(header + "0,1e300,0,0\n90,1e300,1e300,1e300\n180,1e300,0,0\n")
    (tmp / "e31.csv").write_text(header + "0,1e31,0,0\n90,1,1,1\n180,1,0,0\n")
    (tmp / "e29.csv").write_text(header + "0,1e29,0,0\n90,1e29,1e29,1e29\n180,1e29,0,0\n")
    rows = "".join(
        f"{180 * i / 2_000_000!r},1,{0 if i in (0, 2_000_000) else 1},0\n" for i in range(2_000_001)
    )
    (tmp / "huge.csv").write_text(header + rows)
    (tmp / "binary.csv").write_bytes(os.urandom(4096))
    for label, table in [
        ("fifo", str(fifo)),
        ("urandom", "/dev/urandom"),
        ("zero", "/dev/zero"),
        ("null", "/dev/null"),
        ("dir", str(tmp / "dir.csv")),
        ("1e300", "big.csv"),
        ("1e31", "e31.csv"),
        ("1e29", "e29.csv"),
        ("2e6rows", "huge.csv"),
        ("binary", "binary.csv"),
    ]:
        scene = _table_scene(tmp, f"table_{label}", table)
        add(f"validate table {label}", "validate", scene, "--samples", "1")
    add("pointing table 1e29", "pointing", _table_scene(tmp, "t29b", "e29.csv"), "--wind", "10")
    add("reactions table 1e29", "reactions", _table_scene(tmp, "t29c", "e29.csv"), "--wind", "30")

    # drive parameters at the extremes of what the reader accepts (1e30 … 1e-30)
    for key, value in [
        ("C_r", "1e30"),
        ("C_r", "1e-30"),
        ("D_r", "1e30"),
        ("i_r", "1e30"),
        ("i_r", "1e-30"),
        ("L_a", "1e-30"),
        ("L_a", "1e30"),
        ("J_m", "1e-30"),
        ("R_a", "1e30"),
        ("c_m", "1e30"),
    ]:
        scene = _drive(tmp, f"drive_{key}_{value}", key, value)
        add(f"validate drive {key}={value}", "validate", scene, "--samples", "1")
        add(f"modes drive {key}={value}", "modes", scene)
        add(f"simulate hold drive {key}={value}", "simulate", scene, "--t-end", "1")
    for key, value in [("C_r", "1e30"), ("i_r", "1e-30"), ("L_a", "1e-30")]:
        scene = _drive(tmp, f"drive2_{key}_{value}", key, value)
        add(f"plant drive {key}={value}", "plant", scene)
        add(f"pointing drive {key}={value}", "pointing", scene, "--wind", "10")
        add(f"reactions drive {key}={value}", "reactions", scene, "--elevation", "45")
    hold = _drive(tmp, "hold_C_r_1e20", "C_r", "1e20")
    add("simulate hold C_r=1e20", "simulate", hold, "--t-end", "5")
    hold = _drive(tmp, "hold_C_r_1e16", "C_r", "1e16")
    add("simulate hold C_r=1e16", "simulate", hold, "--t-end", "5")

    # other extension elements at extremes
    variants = {
        "wind area 1e30": ('area="3848.4510006474966"', 'area="1e30"'),
        "wind length 1e30": ('length="70"', 'length="1e30"'),
        "air density 1e30": ('<rt70:air density="1.225"/>', '<rt70:air density="1e30"/>'),
        "air density 1e-30": ('<rt70:air density="1.225"/>', '<rt70:air density="1e-30"/>'),
        "gravity 1e30": ('<rt70:gravity xyz="0 0 -9.81"/>', '<rt70:gravity xyz="0 0 -1e30"/>'),
        "optical point 1e30": (
            'name="main_mirror_focus" link="main_mirror" xyz="0 0 13"',
            'name="main_mirror_focus" link="main_mirror" xyz="0 0 1e30"',
        ),
        "sector radius 1e30": ('radius="16"', 'radius="1e30"'),
        "sector radius 1e-30": ('radius="16"', 'radius="1e-30"'),
    }
    for label, (old, new) in variants.items():
        scene = _servo_variant(tmp, label.replace(" ", "_"), old, new)
        add(f"validate {label}", "validate", scene, "--samples", "1")
        add(f"pointing {label}", "pointing", scene, "--wind", "10")
        add(f"reactions {label}", "reactions", scene, "--elevation", "45", "--wind", "10")
    four = (ROOT / "urdf" / "four_bar.urdf").read_text()
    loop_far = tmp / "loop_far.urdf"
    loop_far.write_text(
        four.replace(
            'xyz="0.45 0 0" rpy="0 0 0"/>\n  </rt70:loop>',
            'xyz="1e30 0 0" rpy="0 0 0"/>\n  </rt70:loop>',
        )
    )
    add("validate loop 1e30", "validate", str(loop_far), "--samples", "1")
    add("modes loop 1e30", "modes", str(loop_far))
    add("simulate loop 1e30", "simulate", str(loop_far), "--t-end", "1")

    # pointing
    for w in ("1e10", "1e300", "1e-300", "500"):
        add(f"pointing --wind {w}", "pointing", "rt70_servo", "--wind", w)
    add("pointing --duration 1e12", "pointing", "rt70_servo", "--wind", "10", "--duration", "1e12")
    add("pointing --duration 1e8", "pointing", "rt70_servo", "--wind", "10", "--duration", "1e8")
    add(
        "pointing --direction 1e300",
        "pointing",
        "rt70_servo",
        "--wind",
        "10",
        "--direction",
        "1e300",
    )
    add("pointing --azimuth 1e300", "pointing", "rt70_servo", "--wind", "10", "--azimuth", "1e300")
    add(
        "pointing --seed 2**80",
        "pointing",
        "rt70_servo",
        "--wind",
        "10",
        "--duration",
        "2",
        "--seed",
        str(2**80),
    )
    add(
        "pointing --elevation 0 wind 60",
        "pointing",
        "rt70_servo",
        "--wind",
        "60",
        "--elevation",
        "0",
    )

    # reactions
    for w in ("1e10", "1e300", "1e-300"):
        add(f"reactions --wind {w}", "reactions", "rt70_servo", "--elevation", "45", "--wind", w)
    add(
        "reactions --direction 1e300",
        "reactions",
        "rt70_servo",
        "--elevation",
        "45",
        "--wind",
        "10",
        "--direction",
        "1e300",
    )
    add(
        "reactions --azimuth 1e300",
        "reactions",
        "rt70_servo",
        "--elevation",
        "45",
        "--azimuth",
        "1e300",
    )
    add(
        "reactions 10k elevations",
        "reactions",
        "rt70_servo",
        "--elevation",
        ",".join(["45"] * 10_000),
    )

    # modes, plant
    add("modes --azimuth 1e300", "modes", "rt70_servo", "--azimuth", "1e300")
    add("modes rt70 --elevation 0", "modes", "rt70", "--elevation", "0")
    add("modes --json rt70", "modes", "rt70", "--json")
    add("plant --reduce 10000", "plant", "rt70_servo", "--reduce", "10000")
    add("plant --reduce 1", "plant", "rt70_servo", "--reduce", "1")
    add("plant --azimuth 1e300", "plant", "rt70_servo", "--azimuth", "1e300")
    add(
        "plant --elevation 88.99 reduce",
        "plant",
        "rt70_servo",
        "--elevation",
        "88.99",
        "--reduce",
        "4",
    )

    # simulate
    add("simulate --t-end 1e12", "simulate", "rt70_servo", "--t-end", "1e12")
    add("simulate --t-end 1e7", "simulate", "rt70_servo", "--t-end", "1e7")
    add("simulate rt70 --t-end 1e12", "simulate", "rt70", "--t-end", "1e12")
    add("simulate --t-end 1e-300", "simulate", "rt70_servo", "--t-end", "1e-300")
    add("simulate rt70 --t-end 1e-300", "simulate", "rt70", "--t-end", "1e-300")
    add(
        "simulate step-el at 90",
        "simulate",
        "rt70_servo",
        "--scenario",
        "step-elevation",
        "--elevation",
        "90",
        "--t-end",
        "3",
    )
    add(
        "simulate step-el at 0",
        "simulate",
        "rt70_servo",
        "--scenario",
        "step-elevation",
        "--elevation",
        "0",
        "--t-end",
        "3",
    )
    add(
        "simulate step-el at 89.5",
        "simulate",
        "rt70_servo",
        "--scenario",
        "step-elevation",
        "--elevation",
        "89.5",
        "--t-end",
        "3",
    )
    add(
        "simulate step-az short",
        "simulate",
        "rt70_servo",
        "--scenario",
        "step-azimuth",
        "--t-end",
        "0.5",
    )
    add("simulate track short", "simulate", "rt70_servo", "--scenario", "track", "--t-end", "0.5")
    add("simulate --azimuth 1e300", "simulate", "rt70_servo", "--azimuth", "1e300", "--t-end", "1")
    add("simulate --rtol 0.9", "simulate", "rt70_servo", "--rtol", "0.9", "--t-end", "2")
    add("simulate RK45 hold", "simulate", "rt70_servo", "--method", "RK45", "--t-end", "5")
    add("simulate rt70 RK23", "simulate", "rt70", "--method", "RK23", "--t-end", "10")
    add(
        "simulate --out csv 1e5",
        "simulate",
        "rt70_servo",
        "--t-end",
        "1e5",
        "--out",
        str(tmp / "o.csv"),
    )

    # cart
    add("cart --step 1e-9", "cart", "--step", "1e-9")
    add("cart --step 1e-6 --duration 100", "cart", "--step", "1e-6", "--duration", "100")
    add("cart --duration 1e-300", "cart", "--duration", "1e-300", "--step", "1e-300")
    add("cart --start 1e300", "cart", "--start", "1e300", "1e300")
    add("cart --start 1e10", "cart", "--start", "1e10", "0")
    add("cart --start on obstacle", "cart", "--start", "2", "0")
    add("cart --start origin", "cart", "--start", "0", "0")
    add("cart --heading-error 1e300", "cart", "--heading-error", "1e300")
    add("cart --speed-error 1e300", "cart", "--speed-error", "1e300")
    add("cart --speed-error 1e10", "cart", "--speed-error", "1e10")
    add("cart --speed-error -0.9999999", "cart", "--speed-error", "-0.9999999")

    # impact
    for r in ("1e300", "1e10", "1e200"):
        add(f"impact --rate {r}", "impact", "rt70", "--brake", "base_rx", "--rate", f"base_rx={r}")
    add(
        "impact --rate 1e300 pin",
        "impact",
        "rt70",
        "--pin",
        "main_mirror",
        "--rate",
        "platform_rz=1e300",
    )
    add("impact --pin 1e300", "impact", "rt70", "--pin", "main_mirror:1e300,0,0")
    add("impact --after 1e12", "impact", "rt70", "--brake", "base_rx", "--after", "1e12")
    add("impact --after 1e-300", "impact", "rt70", "--brake", "base_rx", "--after", "1e-300")
    add(
        "impact --seed 2**80",
        "impact",
        "rt70",
        "--brake",
        "base_rx",
        "--state",
        "random",
        "--seed",
        str(2**80),
    )
    add(
        "impact --json rate 1e300",
        "impact",
        "rt70",
        "--brake",
        "base_rx",
        "--rate",
        "base_rx=1e300",
        "--json",
    )
    add(
        "impact servo rate 1e200 after",
        "impact",
        "rt70_servo",
        "--brake",
        "base_rx",
        "--rate",
        "base_rx=1e200",
        "--after",
        "0.01",
    )

    # bench
    add("bench --K 10**12", "bench", "--K", str(10**12))
    add("bench --out /dev/null", "bench", "--quick", "--out", "/dev/null")
    return c


def run_case(case: Case, timeout: float) -> tuple[str, str, float]:
    env = dict(
        os.environ,
        PYTHONPATH=str(ROOT),
        MPLBACKEND="Agg",
        OMP_NUM_THREADS="1",
        OPENBLAS_NUM_THREADS="1",
        MKL_NUM_THREADS="1",
        PYTHONWARNINGS="",
        RT70_WARM="0",  # its own interpreter: the address-space limit is this process's
    )

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))

    start = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "rt70", *case.argv],
            capture_output=True,
            text=True,
            timeout=timeout,
            env=env,
            preexec_fn=limit,
            stdin=subprocess.DEVNULL,
        )
    except subprocess.TimeoutExpired:
        return "hang", f"no exit in {timeout:g} s", time.perf_counter() - start
    seconds = time.perf_counter() - start
    err = [line for line in proc.stderr.splitlines() if line.strip()]
    if "Traceback" in proc.stderr:
        return "traceback", err[-1][:200] if err else "", seconds
    if any(WARNING.search(line) and not line.startswith("rt70: ") for line in err):
        first = next(line for line in err if WARNING.search(line))
        return "warning", first[:200], seconds
    if proc.returncode == 2:
        if len(err) == 1 and err[0].startswith("rt70: error:"):
            return "clean", err[0][:200], seconds
        return "unclear", " | ".join(err)[:200], seconds
    if proc.returncode == 0:
        match = NAN.search(proc.stdout)
        if match:
            line = next(x for x in proc.stdout.splitlines() if NAN.search(x))
            return "nan", line.strip()[:200], seconds
        return "clean", "exit 0", seconds
    return "unclear", f"exit {proc.returncode}: " + " | ".join(err)[-200:], seconds


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--only", default="", help="run the cases whose name contains this")
    parser.add_argument("--start", default="", help="skip the cases before the one named so")
    parser.add_argument("--jobs", type=int, default=1)
    args = parser.parse_args()
    counts: dict[str, int] = {}
    with tempfile.TemporaryDirectory(prefix="rt70-hostile-") as tmp:
        selected = [c for c in cases(Path(tmp)) if args.only in c.name]
        if args.start:
            first = next(i for i, c in enumerate(selected) if c.name == args.start)
            selected = selected[first:]
        with ThreadPoolExecutor(args.jobs) as pool:
            outcomes = pool.map(lambda case: run_case(case, args.timeout), selected)
            for case, (verdict, detail, seconds) in zip(selected, outcomes, strict=True):
                counts[verdict] = counts.get(verdict, 0) + 1
                print(f"{verdict:<9} {seconds:6.1f} s  {case.name:<36} {detail}", flush=True)
    total = sum(counts.values())
    print(f"{total} cases: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    return 0 if counts.get("clean", 0) == total else 1


if __name__ == "__main__":
    sys.exit(main())
