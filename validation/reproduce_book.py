"""Reproduce the book's printed results: writes validation/results/book.md.

Run: ``python validation/reproduce_book.py [OUT_DIR]`` (a few seconds).
"""

import sys
from pathlib import Path

from rt70.reports.book import reproduce

if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "results"
    print(f"wrote {reproduce(out)}")
