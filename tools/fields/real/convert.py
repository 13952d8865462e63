#!/usr/bin/env python3
"""Convert public parcel samples (GeoPackage, ESRI shapefile, WKT) to WGS-84 GeoJSON.

Usage:
    python3 tools/fields/real/convert.py list SOURCE_FILE EPSG
        one line per parcel: index, id, area (ha), holes, vertices, convexity
        (area / convex hull area), thinness (area / (perimeter/4)^2, 1 for a square)
    python3 tools/fields/real/convert.py extract SOURCE_FILE EPSG INDEX OUT.geojson NAME [NOTE]
        writes parcel INDEX (0-based, file order) as a GeoJSON FeatureCollection of one
        Polygon Feature (exterior CCW, holes CW, RFC 7946), projected with pyproj.
    python3 tools/fields/real/convert.py wkt WKT_FILE OUT.geojson NAME [NOTE]
        a WKT POLYGON already in lon/lat (EPSG:4326).

Readers (no GDAL): GeoPackage through sqlite3 (GeoPackage binary header + WKB), shapefiles
(polygon type 5, rings by orientation) and WKT polygons. Needs `pip install pyproj`.
Coordinates are written with 9 decimals (0.1 mm). The README next to this file lists every
field's source, licence and the command that made it.
"""
import json
import math
import os
import re
import sqlite3
import struct
import sys


def wkb_polygons(b, off=0):
    """Polygons (lists of rings of (x, y)) of a WKB geometry; returns (polygons, offset)."""
    order = "<" if b[off] == 1 else ">"
    (t,) = struct.unpack_from(order + "I", b, off + 1)
    off += 5
    has_z = bool(t & 0x80000000) or (t % 10000) // 1000 in (1, 3)
    has_m = bool(t & 0x40000000) or (t % 10000) // 1000 in (2, 3)
    base = (t & 0x0FFFFFFF) % 1000
    dims = 2 + has_z + has_m
    if base == 3:
        (nr,) = struct.unpack_from(order + "I", b, off)
        off += 4
        rings = []
        for _ in range(nr):
            (n,) = struct.unpack_from(order + "I", b, off)
            off += 4
            pts = []
            for _ in range(n):
                v = struct.unpack_from(order + "d" * dims, b, off)
                off += 8 * dims
                pts.append((v[0], v[1]))
            rings.append(pts)
        return [rings], off
    if base == 6:
        (n,) = struct.unpack_from(order + "I", b, off)
        off += 4
        out = []
        for _ in range(n):
            p, off = wkb_polygons(b, off)
            out.extend(p)
        return out, off
    raise ValueError(f"WKB type {t} is not a (multi)polygon")


def gpkg_geometry(blob):
    """WKB of a GeoPackage binary geometry (header 'GP', version, flags, srs id, envelope)."""
    if blob[:2] != b"GP":
        return blob
    flags = blob[3]
    env = (flags >> 1) & 7
    size = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}[env]
    return blob[8 + size:]


def read_gpkg(path):
    con = sqlite3.connect(os.path.abspath(path))
    (table, col) = con.execute(
        "select table_name, column_name from gpkg_geometry_columns limit 1"
    ).fetchone()
    cols = [r[1] for r in con.execute(f'pragma table_info("{table}")')]
    out = []
    for row in con.execute(f'select * from "{table}"'):
        rec = dict(zip(cols, row))
        blob = rec.pop(col)
        if blob is None:
            continue
        polys, _ = wkb_polygons(gpkg_geometry(blob))
        out.append((rec, polys))
    return out


def signed_area(ring):
    return 0.5 * sum(
        ring[i][0] * ring[(i + 1) % len(ring)][1] - ring[(i + 1) % len(ring)][0] * ring[i][1]
        for i in range(len(ring))
    )


def read_shp(path):
    """Polygon shapefile (type 5): outer rings clockwise, holes counter-clockwise."""
    d = open(path, "rb").read()
    off = 100
    out = []
    idx = 0
    while off < len(d):
        (_, length) = struct.unpack_from(">ii", d, off)
        rec = d[off + 8 : off + 8 + 2 * length]
        off += 8 + 2 * length
        (shape,) = struct.unpack_from("<i", rec, 0)
        if shape != 5:
            continue
        nparts, npts = struct.unpack_from("<ii", rec, 36)
        parts = list(struct.unpack_from("<" + "i" * nparts, rec, 44))
        p0 = 44 + 4 * nparts
        pts = [struct.unpack_from("<dd", rec, p0 + 16 * k) for k in range(npts)]
        polys = []
        for k, s in enumerate(parts):
            e = parts[k + 1] if k + 1 < nparts else npts
            ring = pts[s:e]
            if signed_area(ring) < 0:  # clockwise: an outer ring
                polys.append([ring])
            elif polys:
                polys[-1].append(ring)
        out.append(({"record": idx}, polys))
        idx += 1
    return out


def read_wkt(path):
    text = open(path).read()
    rings = re.findall(r"\(([^()]+)\)", text)
    poly = [[tuple(float(v) for v in p.split()[:2]) for p in r.split(",")] for r in rings]
    return [({"file": os.path.basename(path)}, [poly])]


def read(path):
    if path.endswith(".gpkg"):
        return read_gpkg(path)
    if path.endswith(".shp"):
        return read_shp(path)
    return read_wkt(path)


def convex_hull(pts):
    p = sorted(set(pts))
    if len(p) < 3:
        return p

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lo, hi = [], []
    for q in p:
        while len(lo) >= 2 and cross(lo[-2], lo[-1], q) <= 0:
            lo.pop()
        lo.append(q)
    for q in reversed(p):
        while len(hi) >= 2 and cross(hi[-2], hi[-1], q) <= 0:
            hi.pop()
        hi.append(q)
    return lo[:-1] + hi[:-1]


def stats(poly):
    outer = poly[0]
    area = abs(signed_area(outer)) - sum(abs(signed_area(h)) for h in poly[1:])
    hull = abs(signed_area(convex_hull(outer)))
    per = sum(math.dist(outer[i], outer[(i + 1) % len(outer)]) for i in range(len(outer)))
    return area, len(poly) - 1, len(outer), area / hull if hull else 0, area / (per / 4) ** 2


def transformer(epsg):
    from pyproj import Transformer

    return Transformer.from_crs(f"EPSG:{epsg}", "EPSG:4326", always_xy=True)


def to_lonlat(poly, epsg):
    if epsg == 4326:
        rings = [list(r) for r in poly]
    else:
        tr = transformer(epsg)
        rings = [[tr.transform(x, y) for x, y in r] for r in poly]
    out = []
    for k, r in enumerate(rings):
        if r[0] != r[-1]:
            r = r + [r[0]]
        ccw = signed_area(r[:-1]) > 0
        if (k == 0) != ccw:
            r = r[::-1]
        out.append([[round(x, 9), round(y, 9)] for x, y in r])
    return out


def write(poly, epsg, out, name, note, props):
    fc = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {"name": name, "source_note": note, **props},
                "geometry": {"type": "Polygon", "coordinates": to_lonlat(poly, epsg)},
            }
        ],
    }
    with open(out, "w") as f:
        json.dump(fc, f, separators=(",", ":"))
        f.write("\n")


def main(argv):
    cmd = argv[1]
    if cmd == "list":
        # Areas in the source's (metric) CRS; for EPSG:4326 sources convert first.
        for i, (rec, polys) in enumerate(read(argv[2])):
            for j, p in enumerate(polys):
                a, holes, nv, conv, thin = stats(p)
                rid = next(iter(rec.values()), "")
                print(
                    f"{i}.{j} id={rid} ha={a / 1e4:.2f} holes={holes} v={nv} "
                    f"convexity={conv:.3f} squareness={thin:.3f}"
                )
    elif cmd == "extract":
        path, epsg, index, out, name = argv[2], int(argv[3]), argv[4], argv[5], argv[6]
        note = argv[7] if len(argv) > 7 else ""
        i, _, j = index.partition(".")
        rec, polys = read(path)[int(i)]
        props = {k: v for k, v in rec.items() if isinstance(v, (str, int, float))}
        write(polys[int(j or 0)], epsg, out, name, note, props)
    elif cmd == "wkt":
        path, out, name = argv[2], argv[3], argv[4]
        note = argv[5] if len(argv) > 5 else ""
        rec, polys = read_wkt(path)[0]
        write(polys[0], 4326, out, name, note, rec)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
