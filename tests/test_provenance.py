"""The run header every script-written result page carries (rt70.reports.provenance)."""

from __future__ import annotations

import re
from datetime import date

from rt70.reports.provenance import ROOT, command_line, commit, headed, run_header

#: The format tests/test_front_door.py checks on every results page.
HEADER = re.compile(r"> `[^`]+` · commit [0-9a-f]{7,40} · \d{4}-\d{2}-\d{2}")


def test_the_header_has_the_checked_format():
    line = run_header("python validation/x.py --rounds 9", "1a2b3c4", date(2026, 11, 26))
    assert line == "> `python validation/x.py --rounds 9` · commit 1a2b3c4 · 2026-11-26"
    assert HEADER.fullmatch(line)


def test_the_checkout_gives_its_commit():
    assert re.fullmatch(r"[0-9a-f]{7,40}|unknown", commit())
    assert commit(ROOT / "no-such-directory") == "unknown"


def test_the_command_is_the_scripts_path_in_the_checkout():
    script = str(ROOT / "validation" / "x.py")
    assert command_line([script, "--rounds", "9"]) == "python validation/x.py --rounds 9"
    assert command_line(["/elsewhere/y.py", "a b"]) == "python /elsewhere/y.py 'a b'"


def test_the_header_goes_under_the_title_once():
    header = run_header("python validation/x.py", "1a2b3c4", date(2026, 11, 26))
    page = "# Title\n\nFirst paragraph.\n"
    once = headed(page, header)
    assert once == f"# Title\n\n{header}\n\nFirst paragraph.\n"
    later = run_header("python validation/x.py", "5d6e7f8", date(2026, 11, 27))
    assert headed(once, later) == f"# Title\n\n{later}\n\nFirst paragraph.\n"
