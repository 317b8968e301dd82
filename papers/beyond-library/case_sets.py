"""The independent-integrator case sets the summaries read, each given on the command line as
CASES:REPORTS:LIBRARY_RESIDUAL: the cases (each with answer.json), their reports
(REPORTS/CASE/report.json, `motorcal diagnose --rank-only --json`) and the table
`library_residual CASES/*/` prints (what the library's best single term leaves of each
noise-free miss). Shared by kind_table.py and rule_breaks.py."""
import json, os, re


def library_left(table):
    """{case: nats the library's best single term leaves}, from the library-residual table."""
    left = {}
    for line in open(table):
        c = [x.strip() for x in line.split("|")]
        if len(c) > 5 and re.match(r"[a-z_]+-\d+$", c[1]):
            left[c[1]] = float(c[4])
    return left


def cases_with_reports(triples):
    """(case, answer, report, nats left by the library's best term) for every case of the
    CASES:REPORTS:LIBRARY_RESIDUAL triples that has a report, in order."""
    for triple in triples:
        cases, reports, residual = triple.split(":")
        left = library_left(residual)
        for case in sorted(os.listdir(cases)):
            path = os.path.join(reports, case, "report.json")
            if not os.path.exists(path):
                continue
            answer = json.load(open(os.path.join(cases, case, "answer.json")))
            yield case, answer, json.load(open(path)), left.get(case, float("nan"))
