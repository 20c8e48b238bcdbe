#!/usr/bin/env python3
"""Copies a figure's verdict rows from its `verdict.md` into its section of a doc.

    python3 docs/verdict_rows.py FIGURE DIR/FIGURE/verdict.md [--doc docs/reproduction.md]
                                 [--heading "**Verdicts (quick):**"]

The section is the one headed `## \`FIGURE\``; the table replaced is the first after the
heading line (`**Verdicts (quick):**` by default) in it: its header and separator lines stay,
its rows become the rows of `verdict.md`'s table. A doc's verdicts are then the figure's own,
written by the same code that decided them (issue 54). Exits 1, writing nothing, when the
section, the heading or a table is missing.
"""
import argparse
import sys


def rows_of(verdict_md):
    lines = open(verdict_md, encoding="utf-8").read().split("\n")
    start = lines.index("## Verdicts")
    table = [l for l in lines[start:] if l.startswith("| ")]
    return table[1:]  # without the header; the separator does not start with "| "


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("figure")
    ap.add_argument("verdict")
    ap.add_argument("--doc", default="docs/reproduction.md")
    ap.add_argument("--heading", default="**Verdicts (quick):**")
    a = ap.parse_args()
    lines = open(a.doc, encoding="utf-8").read().split("\n")
    try:
        sec = lines.index(f"## `{a.figure}`")
    except ValueError:
        sys.exit(f"{a.doc}: no section '## `{a.figure}`'")
    end = next((k for k in range(sec + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
    head = next((k for k in range(sec, end) if lines[k].strip() == a.heading), None)
    if head is None:
        sys.exit(f"{a.doc}: no line '{a.heading}' in the section of {a.figure}")
    top = next((k for k in range(head, end) if lines[k].startswith("|")), None)
    if top is None or top + 1 >= end or not lines[top + 1].startswith("|---"):
        sys.exit(f"{a.doc}: no table after '{a.heading}' in the section of {a.figure}")
    first = top + 2
    last = first
    while last < end and lines[last].startswith("|"):
        last += 1
    new = rows_of(a.verdict)
    if not new:
        sys.exit(f"{a.verdict}: no verdict rows")
    lines[first:last] = new
    open(a.doc, "w", encoding="utf-8").write("\n".join(lines))
    print(f"{a.doc}: {a.figure}: {last - first} rows replaced by {len(new)}")


if __name__ == "__main__":
    main()
