#!/usr/bin/env python3
"""Generate the test fields in tools/fields (pure Python, no dependencies, deterministic).

Shapes are defined in local metres (x East, y North) about an origin near 52°N 5°E and
projected to WGS-84 with the local meridian/prime-vertical radii of curvature, which is
accurate to millimetres over a few km. Run: python3 tools/fields/make_fields.py
"""
import json
import math
import os

A = 6378137.0
F = 1 / 298.257223563
E2 = F * (2 - F)
HERE = os.path.dirname(os.path.abspath(__file__))


def to_latlon(origin, pts):
    lat0, lon0 = origin
    phi = math.radians(lat0)
    w = math.sqrt(1 - E2 * math.sin(phi) ** 2)
    m = A * (1 - E2) / w**3  # meridian radius
    n = A / w  # prime vertical radius
    return [
        (lat0 + math.degrees(y / m), lon0 + math.degrees(x / (n * math.cos(phi))))
        for x, y in pts
    ]


def rotate(pts, deg, about=(0.0, 0.0)):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    ax, ay = about
    return [(ax + c * (x - ax) - s * (y - ay), ay + s * (x - ax) + c * (y - ay)) for x, y in pts]


def area(pts):
    return 0.5 * sum(
        pts[i][0] * pts[(i + 1) % len(pts)][1] - pts[(i + 1) % len(pts)][0] * pts[i][1]
        for i in range(len(pts))
    )


def ring(origin, pts, ccw=True):
    if (area(pts) > 0) != ccw:
        pts = pts[::-1]
    ll = to_latlon(origin, pts)
    coords = [[round(lon, 9), round(lat, 9)] for lat, lon in ll]
    return coords + [coords[0]]


def feature(origin, outer, holes=(), props=None):
    rings = [ring(origin, outer)] + [ring(origin, h, ccw=False) for h in holes]
    return {
        "type": "Feature",
        "properties": props or {},
        "geometry": {"type": "Polygon", "coordinates": rings},
    }


def write_geojson(name, features):
    doc = {"type": "FeatureCollection", "features": features}
    with open(os.path.join(HERE, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def main():
    # 1. Rectangle, 400 m × 250 m (10 ha), axis-aligned.
    o = (52.0, 5.0)
    write_geojson("rectangle.geojson", [feature(o, rect(0, 0, 400, 250), props={"name": "rectangle"})])

    # 2. Trapezoid rotated by 27°: 500 m base, 300 m top, 260 m high.
    o = (52.01, 5.02)
    trap = rotate([(0, 0), (500, 0), (400, 260), (100, 260)], 27)
    write_geojson("trapezoid_rotated.geojson", [feature(o, trap, props={"name": "trapezoid_rotated"})])

    # 3. L-shape: 500 × 400 m minus the 300 × 250 m top-right corner.
    o = (52.02, 5.04)
    l_shape = [(0, 0), (500, 0), (500, 150), (200, 150), (200, 400), (0, 400)]
    write_geojson("l_shape.geojson", [feature(o, rotate(l_shape, 8), props={"name": "l_shape"})])

    # 4. U-shape: 600 × 400 m with a 200 × 280 m notch from the top.
    o = (52.03, 5.06)
    u_shape = [(0, 0), (600, 0), (600, 400), (400, 400), (400, 120), (200, 120), (200, 400), (0, 400)]
    write_geojson("u_shape.geojson", [feature(o, rotate(u_shape, -12), props={"name": "u_shape"})])

    # 5. Irregular convex 12-gon of exactly 100 ha with a pond (hole) and a pylon (obstacle
    #    feature).
    o = (52.04, 5.08)
    radii = [560, 610, 590, 540, 575, 630, 600, 555, 585, 620, 570, 545]
    angles = [0, 28, 61, 88, 121, 149, 182, 208, 241, 272, 300, 331]
    poly = [(r * math.cos(math.radians(a)), r * math.sin(math.radians(a))) for r, a in zip(radii, angles)]
    k = math.sqrt(1_000_000 / area(poly))
    poly = [(k * x, k * y) for x, y in poly]
    pond = [(120 + 40 * math.cos(t), -80 + 25 * math.sin(t)) for t in (i * math.tau / 10 for i in range(10))]
    pylon = rect(-210, 150, -200, 160)
    write_geojson(
        "irregular_100ha.geojson",
        [
            feature(o, poly, holes=[pond], props={"name": "irregular_100ha"}),
            feature(o, pylon, props={"name": "pylon", "obstacle": True}),
        ],
    )

    # 6. Curved edge: 500 m wide, straight sides 200 m, top is a circular arc (radius 600 m)
    #    of 150 short edges bulging north (convex).
    o = (52.05, 5.10)
    r = 600.0
    half = math.asin(250 / r)
    cy = 200 - r * math.cos(half)
    arc = [
        (250 + r * math.sin(half - 2 * half * i / 150), cy + r * math.cos(half - 2 * half * i / 150))
        for i in range(151)
    ]
    curved = [(0, 0), (500, 0)] + arc[:]  # arc runs from (500, 200) to (0, 200)
    write_geojson("curved_edge.geojson", [feature(o, curved, props={"name": "curved_edge"})])

    # 7. 1000 ha convex hexagon for the scaling benchmark.
    o = (52.10, 5.20)
    hexagon = [(0, 0), (3400, 0), (3900, 1500), (3300, 3100), (500, 3300), (-300, 1600)]
    k = math.sqrt(10_000_000 / area(hexagon))
    hexagon = [(k * x, k * y) for x, y in hexagon]
    write_geojson("large_1000ha.geojson", [feature(o, hexagon, props={"name": "large_1000ha"})])

    # 8. ISO 11783-10 TASKDATA: a convex pentagon with an interior ring (barn) and a separate
    #    obstacle polygon (PLN type 6, a tree group).
    o = (52.06, 5.12)
    pent = [(0, 0), (420, -20), (520, 260), (230, 430), (-60, 250)]
    barn = rect(150, 150, 190, 180)
    trees = [(330 + 15 * math.cos(t), 120 + 15 * math.sin(t)) for t in (i * math.tau / 8 for i in range(8))]

    def pnts(pts):
        return "".join(
            f'<PNT A="2" C="{lat:.9f}" D="{lon:.9f}"/>' for lat, lon in to_latlon(o, pts)
        )

    xml = f"""<?xml version="1.0" encoding="UTF-8"?>
<ISO11783_TaskData VersionMajor="4" VersionMinor="2" ManagementSoftwareManufacturer="agsteer" DataTransferOrigin="1">
<CTR A="CTR1" B="Example farm"/>
<FRM A="FRM1" B="Example farm" I="CTR1"/>
<PFD A="PFD1" C="pentagon" D="{int(area(pent) - 1200 - 700)}" E="CTR1" F="FRM1">
<PLN A="1" B="boundary"><LSG A="1">{pnts(pent)}</LSG><LSG A="2">{pnts(barn[::-1])}</LSG></PLN>
<PLN A="6" B="trees"><LSG A="1">{pnts(trees)}</LSG></PLN>
</PFD>
</ISO11783_TaskData>
"""
    with open(os.path.join(HERE, "pentagon_TASKDATA.XML"), "w") as f:
        f.write(xml)


if __name__ == "__main__":
    main()
