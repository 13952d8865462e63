#!/usr/bin/env python3
"""Derive the test variants of tools/fields/taskdata from the collected files (deterministic;
re-run after changing them and commit the outputs):

- utf16_test1/TASKDATA.XML: isoxml_js_test1/TASKDATA.XML re-encoded as UTF-16 little endian
  with a byte-order mark (encoding="UTF-16" declared), as some terminals write.
- obstacle_line/TASKDATA.XML: isoxml_js_test1's first field with three PLNs added that a
  terminal may hold but that have no obstacle polygon: an obstacle (PLN 6) drawn only as a line
  (LSG 9), a fence (LSG 7) inside the boundary PLN and a headland PLN (type 10).
"""
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))


def read(rel):
    with open(os.path.join(HERE, rel), encoding="utf-8-sig") as f:
        return f.read()


def write(rel, data, encoding):
    os.makedirs(os.path.dirname(os.path.join(HERE, rel)), exist_ok=True)
    with open(os.path.join(HERE, rel), "wb") as f:
        f.write(data.encode(encoding))


src = read("isoxml_js_test1/TASKDATA.XML")
utf16 = re.sub(r'encoding="[^"]*"', 'encoding="UTF-16"', src, count=1)
write("utf16_test1/TASKDATA.XML", "\ufeff" + utf16, "utf-16-le")

# The first PFD only, with the extra PLNs after its boundary PLN.
first = re.search(r"<PFD .*?</PFD>", src, re.S).group(0)
pts = re.findall(r'<PNT A="2" C="([-0-9.]+)" D="([-0-9.]+)"/>', first)
(la, lo), (lb, lob) = [tuple(map(float, p)) for p in pts[:2]]
mid = lambda t: (la + (lb - la) * t, lo + (lob - lo) * t)


def pnt(p):
    return f'<PNT A="2" C="{p[0]:.9f}" D="{p[1]:.9f}"/>'


line = "".join(pnt(mid(t)) for t in (0.3, 0.4, 0.5))
extra = (
    f'<PLN A="6" B="ditch"><LSG A="9" B="ditch line">{line}</LSG></PLN>'
    f'<PLN A="10" B="headland"><LSG A="1">{line}</LSG></PLN>'
)
boundary_fence = first.replace("</LSG>", f'</LSG><LSG A="7" B="fence">{line}</LSG>', 1)
variant = boundary_fence.replace("</PLN>", "</PLN>" + extra, 1)
doc = src[: src.index("<PFD ")] + variant + src[src.rindex("</PFD>") + len("</PFD>") :]
write("obstacle_line/TASKDATA.XML", doc, "utf-8")
