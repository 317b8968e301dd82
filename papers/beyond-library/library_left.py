"""What the library's best single term leaves of each case's noise-free miss, read from the
table `library_residual CASES/*/` prints (examples/library_residual.rs): {case: nats}. Shared
by kind_table.py and rule_breaks.py."""
import re


def library_left(table):
    left = {}
    for line in open(table):
        c = [x.strip() for x in line.split("|")]
        if len(c) > 5 and re.match(r"[a-z_]+-\d+$", c[1]):
            left[c[1]] = float(c[4])
    return left
