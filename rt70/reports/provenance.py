"""The run header of a result page: the command, commit and date that made it.

Every page of ``validation/results/`` that a script writes carries, under its title, one
line ``> `python validation/x.py --option` · commit 1a2b3c4 · 2026-11-26`` (the format
``tests/test_front_door.py`` checks), so that a regenerated page says where it came from
without an edit by hand.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
from datetime import date
from pathlib import Path

#: The repository a result is made in: the checkout this package lies in.
ROOT = Path(__file__).resolve().parents[2]


def command_line(argv: list[str] | None = None) -> str:
    """The command that runs this process, as a user would type it from the checkout.

    ``python validation/x.py --rounds 9`` for a script of the checkout (its path relative
    to the checkout's root), the script's own path otherwise.
    """
    argv = sys.argv if argv is None else argv
    script = Path(argv[0]).resolve()
    shown = script.relative_to(ROOT).as_posix() if script.is_relative_to(ROOT) else argv[0]
    return shlex.join(["python", shown, *argv[1:]])


def commit(root: Path = ROOT) -> str:
    """The checkout's commit, short form, or ``unknown`` outside a git checkout."""
    try:
        proc = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=30,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    return proc.stdout.strip() if proc.returncode == 0 and proc.stdout.strip() else "unknown"


def run_header(command: str, revision: str | None = None, today: date | None = None) -> str:
    """The run header of a result page.

    Parameters
    ----------
    command : str
        The command that made the result, as a user types it.
    revision : str, optional
        The commit (default: this checkout's, :func:`commit`).
    today : datetime.date, optional
        The date of the run (default: today).

    Returns
    -------
    str
        ``> `command` · commit <revision> · <date>``.
    """
    revision = commit() if revision is None else revision
    today = date.today() if today is None else today
    return f"> `{command}` · commit {revision} · {today.isoformat()}"


def headed(text: str, header: str) -> str:
    """The page ``text`` with ``header`` under its title (its first line).

    A header already in its place (the third line, starting ``> ```) is replaced, so a
    page passed twice carries one.
    """
    lines = text.split("\n")
    title, rest = lines[0], lines[1:]
    while rest and not rest[0].strip():
        rest = rest[1:]
    if rest and rest[0].startswith("> `") and " · commit " in rest[0]:
        rest = rest[1:]
        while rest and not rest[0].strip():
            rest = rest[1:]
    return "\n".join([title, "", header, "", *rest])
