#!/usr/bin/env python3
"""The fingerprint of the model as given against the truth's kind, over sets of independent-
integrator cases, on all of them and on those the library does not hold.

    kind_table.py [--outside NATS] CASES:REPORTS:LIBRARY_RESIDUAL ...

CASES is a folder of `beyond_library_cases` cases (each with answer.json), REPORTS the folder
of `motorcal diagnose --json` reports (REPORTS/CASE/report.json), LIBRARY_RESIDUAL the table
`library_residual CASES/*/` printed (what the library's best single term leaves of each
noise-free miss). A case is outside the library where that term leaves at least NATS
(default 10); the table also prints the count at 3, 5, 20 and 30, so that the figure does not
rest on one cut.
"""
import sys

from case_sets import cases_with_reports

args = sys.argv[1:]
cut = 10.0
if args and args[0] == "--outside":
    cut = float(args[1]); args = args[2:]

rows = []
for case, answer, report, nats in cases_with_reports(args):
    given = report.get("unexplained_as_given")
    kind = given["fingerprint"]["kind"] if given else None
    rows.append((case, answer["fingerprint"]["kind"], kind, nats))

print("| case | truth's kind | the model as given's | left by the library's best term (nats) |")
print("|---|---|---|---|")
for case, truth, kind, nats in rows:
    if kind != truth:
        print(f"| {case} | {truth} | {kind or '—'} | {nats:.1f} |")
right = sum(k == t for _, t, k, _ in rows)
print(f"\nall cases: {right} of {len(rows)} of the truth's kind ({100 * right / len(rows):.0f}%); "
      "the table lists the others")
for c in sorted({3.0, 5.0, cut, 20.0, 30.0}):
    out = [(t, k) for _, t, k, n in rows if n >= c]
    r = sum(k == t for t, k in out)
    mark = " (the cut)" if c == cut else ""
    print(f"outside the library (its best term leaves >= {c:g} nats){mark}: {r} of {len(out)}"
          f" ({100 * r / max(len(out), 1):.0f}%)")
