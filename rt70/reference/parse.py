"""Pinocchio's own URDF parser, with its messages turned into rt70's errors and warnings."""

from __future__ import annotations

import os
import sys
import tempfile
import warnings

import pinocchio as pin

from rt70.errors import Rt70Warning, UrdfError
from rt70.guards.resources import run_with_stack


def parse_urdf(text: str, source: str) -> pin.Model:
    """``pin.buildModelFromXML`` with its parser's messages turned into rt70's.

    urdfdom (Pinocchio's parser) prints what it skips or rejects to the process's stderr
    (``Error: <message>`` and an ``at line N in <file>.cpp`` line) and raises a generic
    exception. Its stderr is captured: when it fails, its first message (naming the
    element) is the :class:`~rt70.errors.UrdfError`; when it succeeds, each distinct
    message is an :class:`~rt70.errors.Rt70Warning` (something was skipped).
    """
    sys.stderr.flush()
    saved = os.dup(2)
    error = None
    with tempfile.TemporaryFile() as capture:
        os.dup2(capture.fileno(), 2)
        try:
            # on a large stack: urdfdom recurses per level of the tree
            model = run_with_stack(lambda: pin.buildModelFromXML(text))
        except (RuntimeError, ValueError) as exc:
            error = exc
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        capture.seek(0)
        chatter = capture.read().decode("utf-8", errors="replace")
    messages = []
    for line in chatter.splitlines():
        head, _, message = line.strip().partition(":")
        if head in ("Error", "Warning") and message.strip() and message.strip() not in messages:
            messages.append(" ".join(message.split()))
    if error is not None:
        detail = f"{messages[0]} ({error})" if messages else str(error)
        raise UrdfError(f"{source}: Pinocchio cannot load it: {detail}") from None
    for message in messages:
        warnings.warn(Rt70Warning(f"{source}: Pinocchio's URDF parser: {message}"), stacklevel=3)
    return model
