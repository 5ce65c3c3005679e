"""python3 -m palpate sweep SPEC.json [--out DIR] [--scheduler ADDR] [--workers N] [-q]: as `palpate sweep`."""

import sys

from .sweep import main

if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] != "sweep":
        print("usage: python3 -m palpate sweep SPEC.json [--out DIR] [--scheduler ADDR] [--workers N] [-q]",
              file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[2:]))
