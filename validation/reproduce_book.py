"""Reproduce the book's printed results: writes validation/results/book.md.

Run: ``python validation/reproduce_book.py [OUT_DIR]`` (a few seconds).
"""

import argparse
from pathlib import Path

from rt70.reports.book import reproduce

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "out",
        nargs="?",
        type=Path,
        default=Path(__file__).parent / "results",
        metavar="OUT_DIR",
        help="output directory (default: validation/results)",
    )
    args = parser.parse_args()
    print(f"wrote {reproduce(args.out)}")
