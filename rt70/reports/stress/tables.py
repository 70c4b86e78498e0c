"""The stress report's tables: columns, rows, notes, and their markdown cells."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.reports.stress.runs import RunOutcome


@dataclass
class Table:
    """One table of the report: columns (key, header), rows of values, notes under it."""

    title: str
    intro: str
    columns: list[tuple[str, str]]
    rows: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    summary: dict = field(default_factory=dict)  # numbers the report's findings quote

    def markdown(self) -> str:
        """The table as GitHub markdown, with its introduction and notes."""
        lines = [f"## {self.title}", "", self.intro, ""]
        lines.append("| " + " | ".join(h for _, h in self.columns) + " |")
        lines.append("|" + "|".join("---" for _ in self.columns) + "|")
        for row in self.rows:
            cells = [_cell(row.get(key)) for key, _ in self.columns]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
        lines += [f"- {note}" for note in self.notes]
        lines += ["", f"_Run time of this section: {self.seconds:.1f} s._", ""]
        return "\n".join(lines)


def _cell(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        x = float(value)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf"
        if x == 0.0:
            return "0"
        if 1e-3 <= abs(x) < 1e5:
            return f"{x:.4g}"
        return f"{x:.2e}"
    return str(value).replace("|", "\\|").replace("\n", " ")


SIM_COLUMNS = [
    ("sim", "integration"),
    ("steps", "steps"),
    ("rejected", "rejected"),
    ("nfev", "f evals"),
    ("drift", "energy drift"),
    ("wall", "wall s"),
]


def sim_fields(run: RunOutcome, span: float) -> dict:
    """The simulation columns (:data:`SIM_COLUMNS`) of a row, from a capped run."""
    status = run.status
    if status == "over cap":
        status = f"over cap at t = {run.t_reached:.3g} s of {span:g}"
    return {
        "sim": status,
        "steps": run.n_steps,
        "rejected": run.n_rejected,
        "nfev": run.nfev,
        "drift": run.drift,
        "wall": run.wall_s,
    }


def short_error(exc: Exception) -> str:
    """An error for a table cell (the long gimbal-lock message goes in the notes)."""
    if isinstance(exc, SingularConfigurationError):  # the message is in the notes
        return "SingularConfigurationError"
    return f"{type(exc).__name__}: {exc}"


def worst_value(rows: list[dict], key: str) -> float:
    """The largest float of column ``key`` over ``rows`` (NaN if there is none)."""
    values = [r[key] for r in rows if isinstance(r.get(key), float)]
    return max(values) if values else math.nan
