"""``python -m railfmu`` (also the ``railfmu`` command): run sets from the command line, on
local threads or on a Dask cluster.

    railfmu sweep RUNSET.json -o OUTDIR [--jobs N] [--dask-scheduler ADDRESS] [--resume]
                  [--format csv|parquet]
"""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from . import Error, RunSet


def _sweep(args: argparse.Namespace) -> int:
    if args.jobs is not None and args.dask_scheduler:
        raise Error("--jobs: the runs go to the Dask scheduler's workers; give --jobs or --dask-scheduler, not both")
    rs = RunSet.load(args.runset)
    client = None
    if args.dask_scheduler:
        from distributed import Client

        try:
            client = Client(args.dask_scheduler)
        except (OSError, TimeoutError, ValueError) as e:
            raise Error(f"cannot reach the Dask scheduler '{args.dask_scheduler}': {e}") from None
    try:
        res = rs.run(
            args.output,
            threads=args.jobs,
            client=client,
            progress=not args.quiet and sys.stderr.isatty(),
            resume=args.resume,
            ship_fmus=not args.shared_fmus,
            format=args.format,
        )
    finally:
        if client is not None:
            client.close()
    for r in res.reports:
        if r["ok"]:
            s = r["summary"]
            print(f"{r['name']}: ok, {s['steps']} steps, {s['wall_time_s']:.3f} s wall time")
        else:
            print(f"{r['name']}: FAILED: {r['error']}")
    ok = sum(1 for r in res.reports if r["ok"])
    print(f"{ok} of {len(res.reports)} runs ok; see {res.folder / 'sweep.json'}")
    if res.failed:
        # the first ten names: a set of 100 000 failed runs must not print them all on one line
        names = ", ".join(list(res.failed)[:10])
        if len(res.failed) > 10:
            names += f" and {len(res.failed) - 10} more (see sweep.json)"
        print(f"error: {len(res.failed)} run(s) failed: {names}", file=sys.stderr)
        return 1
    return 0


def _positive(text: str) -> int:
    """A whole number >= 1 (argparse reports a ValueError as an invalid value)."""
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be 1 or more, got {text}")
    return n


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="railfmu", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("sweep", help="run a run set (parameter variations) into a run-set folder")
    s.add_argument("runset", help="run-set description (JSON)")
    s.add_argument("-o", "--output", default="sweep-out", help="output folder (default: sweep-out)")
    s.add_argument("-j", "--jobs", type=_positive, default=None, help="local threads (default: all cores)")
    s.add_argument("--dask-scheduler", metavar="ADDRESS", help="run on this Dask scheduler (e.g. tcp://host:8786)")
    s.add_argument(
        "--resume",
        action="store_true",
        help="keep runs already complete in the output folder in the results format of this sweep "
        "(--format, else by size); runs in the other format run again",
    )
    s.add_argument(
        "--shared-fmus", action="store_true", help="workers read the FMUs from their paths (shared file system) instead of receiving copies"
    )
    s.add_argument(
        "--format",
        choices=("csv", "parquet"),
        default=None,
        help="results format: csv (<run>/results.csv) or parquet (results/<run>.parquet, one table with the "
        "run parameters); default: parquet from 200000 values per run on, as master sweep",
    )
    s.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    args = p.parse_args(argv)
    try:
        return _sweep(args)
    except (Error, ValueError, TypeError) as e:
        # railfmu's errors and its refused options: one line, as master sweep prints them
        print(f"error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted: sweep.json lists every run; --resume runs the others", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
