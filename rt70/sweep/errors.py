"""The errors of a sweep: one that cannot run as asked, and a cluster that cannot finish it."""

from __future__ import annotations

from rt70.errors import Rt70Error


class SweepError(Rt70Error):
    """A sweep that cannot run as asked (bad grid, a foreign partial directory, no cluster)."""


class ClusterError(SweepError):
    """The Dask cluster cannot finish the sweep: its scheduler or its workers are gone."""
