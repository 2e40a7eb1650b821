#!/usr/bin/env python3
# fuzz/make_seeds.py — writes the seed corpora fuzz/corpus/<target>/ (small, valid or nearly valid inputs
# of every form each reader accepts). Rerun after changing it; the files are committed.
import gzip
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
MARK = b"\n--8<--\n"  # fuzz/fuzz_input.h kSplitMarker


def seed(target, name, data):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def text(s):
    return s.lstrip("\n").encode()


def gz(data):
    return gzip.compress(data, mtime=0)


# --- NRRD, attached
seed("nrrd", "raw_uint8.nrrd", text("""
NRRD0004
# 2x2x2 bytes
type: uint8
dimension: 3
sizes: 2 2 2
encoding: raw

""") + bytes(range(8)))
seed("nrrd", "ascii_float.nrrd", text("""
NRRD0005
type: float
dimension: 3
sizes: 2 2 3
spacings: 0.5 1 2
encoding: ascii
content:=free text

0 1.5 -2 3e2, 4 5
6 7 8 9 10 11
"""))
seed("nrrd", "gzip_int16.nrrd", text("""
NRRD0004
type: short
dimension: 3
space: left-posterior-superior
sizes: 2 2 2
space directions: (1,0,0) (0, 2, 0) (0,0,0.5)
space origin: (-1,0,1)
endian: big
encoding: gzip

""") + gz(struct.pack(">8h", -3, -2, -1, 0, 1, 2, 300, 32767)))
seed("nrrd", "4d_double_skips.nrrd", text("""
NRRD0004
type: double
dimension: 4
sizes: 1 2 2 2
space directions: none (1,0,0) (0,1,0) (0,0,1)
endian: little
encoding: raw
byte skip: -1
kinds: scalar space space space

""") + b"junk" + struct.pack("<8d", *[0.25 * i for i in range(8)]))
seed("nrrd", "text_lineskip.nrrd", text("""
NRRD0004
type: unsigned short
dimension: 3
sizes: 2 2 2
encoding: text
line skip: 1

this line is skipped
1 2 3 4 5 6 7 8
"""))

# --- NRRD, detached: header, marker, the file "data"
seed("nrrd_detached", "raw.nhdr", text("""
NRRD0004
type: float
dimension: 3
sizes: 2 2 2
endian: little
encoding: raw
data file: data
""") + MARK[1:] + struct.pack("<8f", *range(8)))
seed("nrrd_detached", "gzip_byteskip.nhdr", text("""
NRRD0004
type: uint16
dimension: 3
sizes: 2 2 2
endian: big
encoding: gz
byte skip: 2
datafile: data
""") + MARK[1:] + gz(b"\0\0" + struct.pack(">8H", *range(8))))
seed("nrrd_detached", "ascii_lineskip.nhdr", text("""
NRRD0004
type: int
dimension: 3
sizes: 2 2 2
encoding: txt
line skip: 1
data file: ./data
""") + MARK[1:] + b"# header line\n-1,2,-3,4\n5 6 7 8\n")
seed("nrrd_detached", "list_two_files.nhdr", text("""
NRRD0004
type: int8
dimension: 3
sizes: 2 2 2
encoding: raw
data file: LIST 3
data
data
""") + MARK[1:] + bytes([1, 2, 3, 4]))
seed("nrrd_detached", "format_missing.nhdr", text("""
NRRD0004
type: uint8
dimension: 3
sizes: 2 2 2
encoding: raw
data file: slice%03d.raw 1 2 1
""") + MARK[1:] + bytes(4))


# --- raw: 11 layout bytes (fuzz/raw.cpp), then the file
def layout(dims, type_code, big, header, spacing):
    return struct.pack("<3h", *dims) + bytes([type_code, (header << 1) | big]) + struct.pack("3b", *spacing)


seed("raw", "uint8", layout((2, 2, 2), 0, 0, 0, (4, 4, 4)) + bytes(range(8)))
seed("raw", "int16_big_header", layout((3, 2, 2), 2, 1, 4, (2, 4, 8)) + b"HDR!" + struct.pack(">12h", *range(-6, 6)))
seed("raw", "float32", layout((2, 2, 2), 6, 0, 0, (1, 1, 1)) + struct.pack("<8f", *[0.5 * i for i in range(8)]))
seed("raw", "float64_big", layout((2, 2, 2), 7, 1, 0, (4, 4, 4)) + struct.pack(">8d", *range(8)))

# --- VTK STRUCTURED_POINTS
seed("vtk_points", "ascii_float.vtk", text("""
# vtk DataFile Version 3.0
a 2x2x2 volume
ASCII
DATASET STRUCTURED_POINTS
DIMENSIONS 2 2 2
SPACING 1 0.5 2
ORIGIN 0 -1 1e1
POINT_DATA 8
SCALARS density float 1
LOOKUP_TABLE default
0 1 2 3
4 5 6 7.5
"""))
seed("vtk_points", "binary_short.vtk", text("""
# vtk DataFile Version 2.0
binary, no lookup table
BINARY
DATASET STRUCTURED_POINTS
DIMENSIONS 2 2 2
ASPECT_RATIO 1 1 1
POINT_DATA 8
SCALARS s short
""") + struct.pack(">8h", *range(-4, 4)))

# --- VTK UNSTRUCTURED_GRID
TET_POINTS = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
seed("vtk_unstructured", "ascii_tet.vtk", text("""
# vtk DataFile Version 3.0
one tetrahedron
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 4 float
""") + TET_POINTS.encode() + text("""
CELLS 1 5
4 0 1 2 3
CELL_TYPES 1
10
POINT_DATA 4
SCALARS temperature double 1
LOOKUP_TABLE default
0 1 2 3
VECTORS v float
0 0 0 1 1 1 2 2 2 3 3 3
"""))
hexPoints = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
hexOrder = [0, 1, 3, 2, 4, 5, 7, 6]
seed("vtk_unstructured", "binary_hex.vtk", text("""
# vtk DataFile Version 3.0
one hexahedron
BINARY
DATASET UNSTRUCTURED_GRID
POINTS 8 double
""") + b"".join(struct.pack(">3d", *p) for p in hexPoints) + b"\nCELLS 1 9\n" +
    struct.pack(">9i", 8, *hexOrder) + b"\nCELL_TYPES 1\n" + struct.pack(">i", 12) +
    b"\nPOINT_DATA 8\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n" + bytes(range(8)) + b"\n")
seed("vtk_unstructured", "v5_wedge_field.vtk", text("""
# vtk DataFile Version 5.1
a wedge and a tetrahedron, 5.x offsets
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 7 float
0 0 0 1 0 0 0 1 0
0 0 1 1 0 1 0 1 1
0 0 2
CELLS 3 10
OFFSETS vtktypeint64
0 6 10
CONNECTIVITY vtktypeint64
0 1 2 3 4 5
3 4 5 6
CELL_TYPES 2
13
10
CELL_DATA 2
SCALARS id int 1
LOOKUP_TABLE default
0 1
POINT_DATA 7
FIELD FieldData 2
pressure 1 7 float
0 1 2 3 4 5 6
velocity 3 7 float
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
METADATA
INFORMATION 0

"""))

# --- TetGen: .node, marker, .ele, [marker, .neigh]
NODE = text("""
# two tetrahedra sharing a face, numbered from 1
5 3 2 1
1 0 0 0 0.5 7 1
2 1 0 0 1.5 7 1
3 0 1 0 2.5 7 0
4 0 0 1 3.5 7 1
5 1 1 1 4.5 7 0
""")
ELE = text("""
2 4 0
1 1 2 3 4
2 2 3 4 5
""")
seed("tetgen", "node_ele", NODE + MARK[1:] + ELE)
seed("tetgen", "node_ele_neigh", NODE + MARK[1:] + ELE + MARK[1:] + text("""
2 4
1 2 -1 -1 -1
2 -1 -1 -1 1
"""))
seed("tetgen", "zero_based_quadratic", text("""
4 3 1 0
0 0 0 0 1
1 1 0 0 2
2 0 1 0 3
3 0 0 1 4
""") + MARK[1:] + text("""
1 10 1
0 0 1 2 3 0 0 0 0 0 0 7
"""))

# --- .off tetrahedral meshes
seed("off_tet", "off_header.off", text("""
OFF
5 2
0 0 0 0.5
1 0 0 1.5
0 1 0 2.5
0 0 1 3.5
1 1 1 4.5
0 1 2 3
4 1 2 3 4
"""))
seed("off_tet", "counts_only.off", text("""
# no OFF line, two scalars per point
4 1
0 0 0 1 9
1 0 0 2 9
0 1 0 3 9
0 0 1 4 9
3 2 1 0
"""))

# --- surfaces: the first byte picks .off, .stl, .poly, .smesh (fuzz/surface.cpp)
TET_POINTS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TET_FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
TET_OFF = ("OFF\n4 4 6\n" + "".join("%d %d %d\n" % p for p in TET_POINTS) +
           "".join("3 %d %d %d\n" % f for f in TET_FACES)).encode()
seed("surface", "tetrahedron.off", b"\0" + TET_OFF)
seed("surface", "triangle.stl", b"\1" + text("""
solid t
  facet normal 0 0 1
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 0 1 0
    endloop
  endfacet
endsolid t
"""))
with open(os.path.join(HERE, "..", "data", "surfaces", "l-block.poly"), "rb") as f:
    lblock = f.read()
seed("surface", "l-block.poly", b"\2" + lblock[lblock.index(b"12 3 0 0"):])
seed("surface", "holes_regions.poly", b"\2" + text("""
# a cube with a facet hole, a volume hole and a region; 1-based, markers
8 3 1 1
1 0 0 0 5 1
2 1 0 0 5 1
3 1 1 0 5 1
4 0 1 0 5 1
5 0 0 1 5 2
6 1 0 1 5 2
7 1 1 1 5 2
8 0 1 1 5 2
2 1
2 1 3
4 1 2 3 4
3 1 2 3
1 0.5 0.5 0
1 0 -1
4 5 6,7 8
1
1 0.5 0.5 0.5
1
1 0.2 0.2 0.2 7 0.01
"""))
seed("surface", "cube.smesh", b"\3" + text("""
8 3 0 0
0 0 0 0
1 1 0 0
2 1 1 0
3 0 1 0
4 0 0 1
5 1 0 1
6 1 1 1
7 0 1 1
6 1
4 0 1 2 3 1
4 4 5 6 7 2
4 0 1 5 4 3
4 1 2 6 5 3
4 2 3 7
6 3
4 3 0 4 7 3
0
0
"""))


# --- PLOT3D: scalar byte, grid, marker, solution (big-endian, 2x2x2)
# --- clip surfaces: the first byte picks .off, .stl (ASCII or binary), .obj (fuzz/clip_surface.cpp)
seed("clip_surface", "tetrahedron.off", b"\0" + TET_OFF)
seed("clip_surface", "tetrahedron.stl", b"\1" + ("solid t\n" + "".join(
    "facet normal 0 0 0\nouter loop\n" + "".join("vertex %g %g %g\n" % TET_POINTS[i] for i in f) + "endloop\nendfacet\n"
    for f in TET_FACES) + "endsolid t\n").encode())
seed("clip_surface", "tetrahedron-binary.stl", b"\1" + b"\0" * 80 + struct.pack("<I", 4) + b"".join(
    struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *TET_POINTS[i]) for i in f) + b"\0\0" for f in TET_FACES))
seed("clip_surface", "tetrahedron.obj", b"\2" + ("# a tetrahedron\n" + "".join("v %g %g %g\n" % p for p in TET_POINTS) +
    "".join("f %d/1/1 %d %d\n" % tuple(i + 1 for i in f) for f in TET_FACES)).encode())


def plot3d(scalar):
    n = 8
    xyz = struct.pack(">3i", 2, 2, 2) + struct.pack(">%df" % n, *[i & 1 for i in range(n)]) + \
        struct.pack(">%df" % n, *[(i >> 1) & 1 for i in range(n)]) + struct.pack(">%df" % n, *[(i >> 2) & 1 for i in range(n)])
    q = struct.pack(">3i", 2, 2, 2) + struct.pack(">4f", 0.5, 10.0, 0.0, 1.0) + \
        struct.pack(">%df" % (5 * n), *([1.0 + i for i in range(n)] + [0.1] * (3 * n) + [2.5] * n))
    return bytes([scalar]) + xyz + MARK + q


for code, name in enumerate(["density", "momentum", "energy", "pressure"]):
    seed("plot3d", name, plot3d(code))

# --- scenes: JSON, optionally marker and --set / --unset lines ("-PATH" unsets)
seed("scene", "generator.json", text("""
{"technique": "slice3d", "volume": {"generator": "marschner-lobb", "dims": [8, 8, 8]},
 "camera": {"position": [3, 2, 4], "focal_point": [0, 0, 0], "view_up": [0, 1, 0], "view_angle": 30},
 "image": {"width": 64, "height": 48, "background": [0, 0, 0.1]},
 "transfer_function": {"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 20]]}, "options": {"slices": 64}}
"""))
seed("scene", "raw_iso_lights.json", text("""
{"technique": "iso3d",
 "volume": {"file": "v.raw", "dims": [4, 4, 4], "type": "int16", "endian": "big", "spacing": [1, 1, 2],
            "origin": [0, 0, -1], "header_bytes": 16},
 "camera": {"position": [0, 0, 5], "focal_point": [0, 0, 0], "projection": "parallel", "parallel_scale": 2},
 "iso": {"value": 100, "shading": "gradientless", "light": [1, -0.6, 0.8], "ambient": 0.2, "diffuse": 0.8},
 "lights": [{"direction": [0, 0, 1], "color": [1, 0.9, 0.8]}],
 "material": {"ambient": 0.1, "diffuse": 0.7, "specular": 0.2, "shininess": 20}}
"""))
seed("scene", "mesh_overrides.json", text("""
{"technique": "harc", "mesh": {"file": "m.vtk", "scalar": "pressure"}, "camera": {"view_angle": 40},
 "transfer_function": {"points": [[0, 0.1, 0.2, 0.8, 0.6], [1, 1, 0.2, 0.1, 8]]}}
""") + MARK[1:] + text("""
camera.view_angle=20
options.slices=64
image={"width":64,"height":64}
technique=tetslice
mesh={"file": "grid.xyz", "q_file": "grid.q"}
-mesh.scalar
-camera
"""))
seed("scene", "surface_mesh.json", text("""
{"technique": "harc",
 "mesh": {"surface": "l-block.poly", "quality": 1.5, "max_volume": 0.001, "scalar": "blobs.nrrd"},
 "iso": {"value": 0.5, "shading": "none"}}
""") + MARK[1:] + text("""
mesh={"generator": "automaton", "cells": 100, "grid": 8}
-iso.shading
"""))
seed("scene", "nrrd_options.json", text("""
{"volume": {"file": "../engine.nhdr"}, "options": {"slices": 512, "clip": {"mesh": {"radius": 0.5}}},
 "transfer_function": {"points": [[0, 0.95, 0.8, 0.6, 0.0], [255, 0.95, 0.8, 0.6, 1.0]]}}
"""))

# --- transfer functions: the value of "transfer_function"
seed("transfer_function", "two_points", text('{"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 20]]}'))
seed("transfer_function", "default_scene", text("""
{"points": [[0.00, 0.00, 0.00, 0.00, 0.0], [0.35, 0.10, 0.20, 0.80, 0.0], [0.45, 0.20, 0.40, 1.00, 2.0],
            [0.55, 0.20, 0.90, 0.50, 0.0], [0.72, 1.00, 0.80, 0.20, 0.0], [0.80, 1.00, 0.50, 0.10, 6.0],
            [0.88, 1.00, 0.20, 0.10, 0.0], [1.00, 1.00, 1.00, 1.00, 20.0]]}
"""))
seed("transfer_function", "wide_range", text('{"points": [[-1e30, 0, 0.5, 1, 0], [-1e-300, 1, 1, 1, 1e10], [3e38, 0, 0, 0, 0.5]]}'))

# --- numpy .npy
def npy(descr, fortran, shape, data, version=1):
    d = "{'descr': '%s', 'fortran_order': %s, 'shape': (%s), }" % (
        descr, "True" if fortran else "False", ", ".join(str(s) for s in shape))
    pre = 10 if version == 1 else 12
    d += " " * ((64 - (pre + len(d) + 1) % 64) % 64) + "\n"
    n = struct.pack("<H", len(d)) if version == 1 else struct.pack("<I", len(d))
    return b"\x93NUMPY" + bytes([version, 0]) + n + d.encode() + data


seed("npy", "u1_c.npy", npy("|u1", False, (2, 3, 2), bytes(range(12))))
seed("npy", "i2_f_big.npy", npy(">i2", True, (2, 2, 2), struct.pack(">8h", *range(-4, 4))))
seed("npy", "f4_v2.npy", npy("<f4", False, (2, 2, 2), struct.pack("<8f", *[0.5 * i for i in range(8)]), 2))
seed("npy", "f8_c.npy", npy("<f8", False, (2, 2, 3), struct.pack("<12d", *range(12))))

# --- VTK XML image data (.vti, .pvti + piece) and unstructured grids (.vtu)
VTI_ASCII = text("""
<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="0 2 0 1 0 1" Origin="0 0 0" Spacing="1 0.5 2" Direction="1 0 0 0 1 0 0 0 1">
  <Piece Extent="0 2 0 1 0 1">
    <PointData Scalars="density">
      <DataArray type="UInt16" Name="density" format="ascii" RangeMin="0" RangeMax="11">
        0 1 2 3 4 5 6 7 8 9 10 11
      </DataArray>
      <DataArray type="Float32" Name="other" format="ascii">
        0 -1 -2 -3 -4 -5 -6 -7 -8 -9 -10 -11
      </DataArray>
    </PointData>
    <CellData>
    </CellData>
  </Piece>
  </ImageData>
</VTKFile>
""")
seed("vti", "ascii.vti", VTI_ASCII)
APPENDED = struct.pack("<Q", 16) + struct.pack("<8H", *range(8))
seed("vti", "appended_raw.vti", text("""
<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="0 1 0 1 0 1" Origin="0 0 0" Spacing="1 1 1">
  <Piece Extent="0 1 0 1 0 1">
    <PointData Scalars="s">
      <DataArray type="UInt16" Name="s" format="appended" offset="0"/>
    </PointData>
  </Piece>
  </ImageData>
  <AppendedData encoding="raw">
   _""") + APPENDED + b"\n  </AppendedData>\n</VTKFile>\n")
seed("vti", "pvti_piece", text("""
<?xml version="1.0"?>
<VTKFile type="PImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PImageData WholeExtent="0 2 0 1 0 1" GhostLevel="0" Origin="0 0 0" Spacing="1 0.5 2">
    <PPointData Scalars="density">
      <PDataArray type="UInt16" Name="density"/>
      <PDataArray type="Float32" Name="other"/>
    </PPointData>
    <Piece Extent="0 2 0 1 0 1" Source="piece.vti"/>
  </PImageData>
</VTKFile>
""") + MARK + VTI_ASCII)
seed("vtu", "ascii.vtu", text("""
<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <UnstructuredGrid>
    <Piece NumberOfPoints="7" NumberOfCells="2">
      <PointData Scalars="t">
        <DataArray type="Float32" Name="t" format="ascii">0 1 2 3 4 5 6</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">
          0 0 0 1 0 0 0 1 0 0 0 1 1 1 0 1 0 1 0 1 1
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3 1 4 2 5 0 6</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4 10</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 13</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"""))
