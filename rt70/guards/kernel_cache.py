"""numba's on-disk cache of rt70's kernels, invalidated when any kernel source changes.

numba keys a cached function by the contents of its own file alone. A kernel compiles
in the kernels it calls from other files (and the constants it reads from them), so when
only such a file changes, its cached code is stale, and numba loads it without a word:
after a ``git pull`` into an editable install, for example, the compiled BDF of
``rt70/simulation/bdf_kernel.py`` would keep the old Newton–Euler pass of
``rt70/textbook/motion_kernel.py``.

:func:`stamp_kernel_caches` puts cache locators in front of numba's own (numba 0.68's
``CacheImpl._locator_classes``) that take the same folders (``NUMBA_CACHE_DIR``, the
package's ``__pycache__``, the user's cache) but stamp every rt70 kernel with
:func:`digest`: the contents of every file of :data:`SOURCES` together. Any change to
one of them makes every rt70 kernel compile again, once. Each module that defines
kernels calls :func:`stamp_kernel_caches` before its first ``numba.njit``.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

#: The package's folder.
PACKAGE = Path(__file__).resolve().parents[1]

#: The files whose code or constants compiled kernels hold, relative to :data:`PACKAGE`:
#: every module with ``numba.njit`` functions, and the modules they import constants
#: from (``tests/test_kernel_cache.py`` checks the first part).
SOURCES = (
    "reference/element_tables.py",
    "reference/forces.py",
    "reference/joint_walk.py",
    "simulation/bdf_kernel.py",
    "simulation/bdf_newton.py",
    "textbook/articulated_kernel.py",
    "textbook/forward_kernel.py",
    "textbook/mass_kernel.py",
    "textbook/motion_kernel.py",
    "textbook/spatial.py",
    "textbook/static_kernel.py",
)


@functools.lru_cache(maxsize=1)
def digest() -> bytes:
    """SHA-256 of the names and contents of :data:`SOURCES`, read once per process."""
    sha = hashlib.sha256()
    for name in SOURCES:
        sha.update(name.encode())
        sha.update((PACKAGE / name).read_bytes())
    return sha.digest()


@functools.lru_cache(maxsize=1)
def _kernel_files() -> frozenset[Path]:
    return frozenset((PACKAGE / name).resolve() for name in SOURCES)


class _KernelStamp:
    """A locator mixin: rt70's kernel files alone, stamped with :func:`digest`."""

    def get_source_stamp(self) -> bytes:
        return digest()

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve() not in _kernel_files():
            return None
        return super().from_function(py_func, py_file)


def stamp_kernel_caches() -> None:
    """Put the kernel locators in front of numba's, each before the one it extends.

    Idempotent. Raises ``AttributeError`` if numba's locator list is not where numba 0.68
    keeps it (a numba that moved it needs this module changed, not silently skipped).
    """
    from numba.core import caching

    classes = caching.CacheImpl._locator_classes
    if any(issubclass(c, _KernelStamp) for c in classes):
        return
    bases = (
        caching.UserProvidedCacheLocator,
        caching.InTreeCacheLocator,
        caching.UserWideCacheLocator,
    )
    for base in bases:
        stamped = type(f"Rt70{base.__name__}", (_KernelStamp, base), {})
        classes.insert(classes.index(base), stamped)
