"""rt70's version: the one place it is written.

pyproject.toml reads it (``[tool.setuptools.dynamic]``) into the distribution's metadata;
``rt70.__version__`` and ``rt70 --version`` import it, which costs nothing, where reading
the installed metadata imported :mod:`importlib.metadata` (41 ms of a 0.15 s start-up
target).
"""

__version__ = "0.2.0"
