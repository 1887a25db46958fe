"""``geoshade summary CASE``: the summary vectors of an ECLIPSE/OPM run as a plot, a CSV, JSON.

``--vector`` picks vectors by their ECLIPSE names (``FOPR``, ``WBHP:PROD``, ``BPR:1,2,3``) or by
wildcards (``'WOPR:*'``); ``--list`` lists them with their units and kinds. The plot has dates
on x and SMSPEC's units on the y axes (:class:`geoshade.styles.summary_plot.SummaryPlot`), with
a cursor at ``--cursor STEP``; the CSV has the date (ISO, to the second), the days and one
column per vector, every ministep, the values as the files store them. Outputs are checked
before anything is read and written together at the end.
"""

from __future__ import annotations

import argparse
import re

from geoshade.errors import InputError
from geoshade.io.formats import case_files
from geoshade.io.grids.summary import csv_text, listing, read_spec, read_summary, summary_files
from geoshade.io.output import Outputs, json_bytes, png_bytes
from geoshade.models.steps import resolve_step
from geoshade.models.summary_vectors import SummaryTable
from geoshade.styles.image import parse_size
from geoshade.styles.summary_plot import SummaryPlot

#: a date (and time) given to --cursor
DATE = re.compile(r"^\s*\d{4}-\d{1,2}-\d{1,2}([ T]\d{1,2}:\d{2}(:\d{2})?)?\s*$")
EXAMPLES = """examples:
  geoshade summary CASE.SMSPEC --list
  geoshade summary CASE.DATA --vector FOPR --vector WBHP:PROD -o plot.png --csv out.csv
  geoshade summary CASE.EGRID --vector 'WOPR:*' --cursor 2016-01-01 -o wells.png
"""


def register(sub) -> None:
    p = sub.add_parser("summary", help="summary vectors of an ECLIPSE/OPM run: plot, CSV, list",
                       description="The summary vectors of an ECLIPSE/OPM run (any file of the "
                                   "case) as a plot, a CSV and JSON.", epilog=EXAMPLES,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", metavar="CASE",
                   help="any file of the case: .SMSPEC, .FSMSPEC, .UNSMRY, .DATA, .EGRID, "
                        ".UNRST, ... (the SMSPEC and its data are found beside it)")
    p.add_argument("-v", "--vector", action="append", metavar="NAME", default=None,
                   help="a vector as ECLIPSE names it (FOPR, WBHP:PROD, GOPR:OP, RPR:2, "
                        "BPR:1,2,3) or a wildcard ('WOPR:*'); repeat for more")
    p.add_argument("--list", action="store_true",
                   help="list the vectors (those --vector names, or all) with unit and kind")
    p.add_argument("-o", "--output", metavar="PLOT.png", help="draw the vectors against time")
    p.add_argument("--csv", metavar="OUT.csv",
                   help="write date, days and one column per vector, every ministep")
    p.add_argument("--stats", metavar="FILE.json",
                   help="write the vectors' ranges, the time span and the plot's layout")
    p.add_argument("--size", default="1000x600", metavar="WxH",
                   help="plot size in pixels (1000x600); under 260 high: a strip, no title")
    p.add_argument("--cursor", metavar="STEP", default=None,
                   help="draw the time cursor at a report step: index (-1 the last), R36 or a "
                        "date YYYY-MM-DD[THH:MM]")
    p.add_argument("--title", default=None, help="plot title (default: the case and its units)")
    p.set_defaults(func=run)


def _vectors_hint(spec) -> str:
    fields = [v.key for v in spec.vectors if v.kind == "field"][:6]
    some = ", ".join(fields) or ", ".join(spec.keys[:6])
    return f"--vector: give the vectors to write, e.g. --vector {(fields or spec.keys)[0]} " \
           f"(this case has {some} ...; --list lists all {len(spec.vectors)})"


def cursor_date(table: SummaryTable, step: str) -> str:
    """The date the cursor goes to: ``step`` itself when it is a date (any date: the markers go
    to the nearest report step), else the date of report step ``step`` (as everywhere: index,
    -1, ``first``, ``last``, ``R36``) among the table's report steps.

    >>> import numpy as np, datetime
    >>> from geoshade.models.summary_vectors import SummaryVector
    >>> t = SummaryTable([1.0, 2.0, 3.0], np.zeros((3, 1), np.float32),
    ...                  [SummaryVector("FPR", "FPR", "field")], datetime.datetime(2000, 1, 1),
    ...                  report=np.array([1, 1, 2]))
    >>> cursor_date(t, "R1"), cursor_date(t, "2000-01-03T12:00")
    ('2000-01-03T00:00:00', '2000-01-03T12:00')
    """
    if DATE.match(str(step)):
        return str(step).strip()
    reports, dates = table.report_steps()
    k = resolve_step(step, len(dates), reports=[int(r) for r in reports], where="--cursor")
    return str(dates[k])


def _stats(table: SummaryTable, files, layout: dict | None, args) -> dict:
    vecs = []
    for i, v in enumerate(table.vectors):
        col = table.values[:, i]
        vecs.append({"name": v.key, "unit": v.unit, "kind": v.kind, "keyword": v.keyword,
                     "min": float(col.min()), "max": float(col.max()),
                     "first": float(col[0]), "last": float(col[-1])})
    reports, _ = table.report_steps()
    out = {"case": str(args.case), "files": [str(files.spec), *map(str, files.data)],
           "unit_system": table.unit_system, "start": table.start.isoformat(),
           "first": table.iso_dates()[0], "last": table.iso_dates()[-1],
           "ministeps": table.nsteps, "report_steps": len(reports), "vectors": vecs,
           "outputs": {k: v for k, v in (("png", args.output), ("csv", args.csv)) if v}}
    if layout is not None:
        out["plot"] = layout
    return out


def run(args) -> int:
    size = parse_size(args.size) if args.output else None
    if not (args.list or args.output or args.csv or args.stats):
        raise InputError("summary: nothing to do; give -o PLOT.png, --csv OUT.csv, --stats "
                         "FILE.json or --list")
    files = summary_files(args.case)
    inputs = [*case_files(args.case), files.spec, *files.data]
    with Outputs({"-o": args.output, "--csv": args.csv, "--stats": args.stats}, inputs=inputs,
                 suffixes={"-o": (".png",), "--csv": (".csv",), "--stats": (".json",)}) as out:
        spec = read_spec(files.spec)
        if args.list:
            chosen = spec.match(args.vector) if args.vector else spec.vectors
            print(f"{files.describe()}: {len(chosen)} of {len(spec.vectors)} vectors"
                  f"{', ' + spec.unit_system + ' units' if spec.unit_system else ''}")
            for line in listing(spec, args.vector):
                print(f"  {line}")
        if not (args.output or args.csv or args.stats):
            return 0
        if not args.vector:
            raise InputError(_vectors_hint(spec))
        spec.match(args.vector)  # an unknown name is one line before the data is read
        table = read_summary(files.spec, args.vector)
        layout = None
        if args.output:
            at = None if args.cursor is None else cursor_date(table, args.cursor)
            plot = SummaryPlot(table, size=size, title=args.title)
            try:
                out.put("-o", png_bytes(plot.draw(at)))
                layout = plot.layout
            finally:
                plot.close()
        elif args.cursor is not None:
            raise InputError("--cursor: the cursor is drawn on the plot; give -o PLOT.png too")
        if args.csv:
            out.put("--csv", csv_text(table).encode("utf-8"))
        if args.stats:
            out.put("--stats", json_bytes(_stats(table, files, layout, args)))
        out.commit()
    reports, _ = table.report_steps()
    where = ", ".join(p for p in (args.output, args.csv, args.stats) if p)
    print(f"{files.describe()}: {len(table.vectors)} vectors ({', '.join(table.keys[:6])}"
          f"{' ...' if len(table.vectors) > 6 else ''}), {table.nsteps} ministeps in "
          f"{len(reports)} report steps, {table.iso_dates()[0]} – {table.iso_dates()[-1]}"
          f"{', ' + table.unit_system + ' units' if table.unit_system else ''} -> {where}")
    return 0


__all__ = ["cursor_date", "register", "run"]
