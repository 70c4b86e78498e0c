"""The links and joints rt70 writes into a URDF text before either side parses it.

One job: run every expansion — :mod:`rt70.urdf.beams` (``<rt70:beam>`` as rigid finite
elements) and :mod:`rt70.urdf.modal_interfaces` (``<rt70:interface>`` chains on a modal
body's nodes) — so that the textbook reader and Pinocchio's parser see the same text.
Each expansion is idempotent: a text already expanded comes back as it is.
"""

from __future__ import annotations

from rt70.urdf.beams import expand_beams
from rt70.urdf.modal_interfaces import expand_interfaces


def expand_generated(text: str, source: str = "<string>") -> str:
    """The text with its beams and modal body interfaces written out (see the modules)."""
    return expand_interfaces(expand_beams(text, source), source)
