"""numba's cache of rt70's kernels, stamped with every kernel source (rt70.guards.kernel_cache).

A kernel whose callee in another file changed must not load its cached code: every
rt70 kernel carries the digest of all kernel sources, and a different digest is a
cache miss (checked end to end in fresh interpreters on a cache folder of its own).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

from rt70.guards import kernel_cache

#: A kernel definition in a module's code.
KERNEL = re.compile(r"^@numba\.njit|^@njit", re.M)


def _kernel_modules() -> set[str]:
    return {
        str(p.relative_to(kernel_cache.PACKAGE))
        for p in kernel_cache.PACKAGE.rglob("*.py")
        if KERNEL.search(p.read_text(encoding="utf-8"))
    }


def test_every_module_with_kernels_is_a_source_and_installs_the_locators_first():
    modules = _kernel_modules()
    assert len(modules) >= 8 and modules <= set(kernel_cache.SOURCES)
    assert all((kernel_cache.PACKAGE / name).is_file() for name in kernel_cache.SOURCES)
    for name in modules:
        text = (kernel_cache.PACKAGE / name).read_text(encoding="utf-8")
        assert 0 < text.find("\nstamp_kernel_caches()") < KERNEL.search(text).start(), name


def test_a_kernel_is_cached_under_the_digest_of_every_source():
    from rt70.simulation import bdf_kernel
    from rt70.textbook import motion_kernel

    for kernel in (bdf_kernel.advance, motion_kernel._newton_euler):
        locator = kernel._cache._impl.locator
        assert isinstance(locator, kernel_cache._KernelStamp)
        assert locator.get_source_stamp() == kernel_cache.digest()


def test_the_digest_changes_with_any_source(tmp_path, monkeypatch):
    for name in kernel_cache.SOURCES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes((kernel_cache.PACKAGE / name).read_bytes())
    monkeypatch.setattr(kernel_cache, "PACKAGE", tmp_path)
    try:
        kernel_cache.digest.cache_clear()
        before = kernel_cache.digest()
        with open(tmp_path / "textbook" / "motion_kernel.py", "a") as fh:
            fh.write("\n# edited\n")
        kernel_cache.digest.cache_clear()
        assert kernel_cache.digest() != before
    finally:
        kernel_cache.digest.cache_clear()


#: A fresh interpreter calls one small kernel and prints numba's cache hits and misses;
#: with an argument it stands for a checkout whose kernel sources differ.
_CHILD = """
import json, sys
import numpy as np
from rt70.guards import kernel_cache
if len(sys.argv) > 1:
    kernel_cache.digest = lambda: b"another checkout's sources"
from rt70.simulation import bdf_kernel
bdf_kernel._norm(np.ones(3), np.ones(3))
stats = bdf_kernel._norm.stats
print(json.dumps([sum(stats.cache_hits.values()), sum(stats.cache_misses.values())]))
"""


def _hits_and_misses(cache_dir, *args: str) -> list[int]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache_dir)}
    done = subprocess.run([sys.executable, "-c", _CHILD, *args], env=env, capture_output=True,
                          text=True, timeout=300, check=True)  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_kernel_compiled_against_other_sources_is_not_loaded(tmp_path):
    assert _hits_and_misses(tmp_path) == [0, 1]  # compiled, saved
    assert _hits_and_misses(tmp_path) == [1, 0]  # the same sources: loaded
    assert _hits_and_misses(tmp_path, "edited") == [0, 1]  # other sources: compiled again
