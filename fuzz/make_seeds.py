#!/usr/bin/python3
"""Writes the seed corpora of the fuzz targets (fuzz/corpus/TARGET) and the regression inputs
(fuzz/regressions/TARGET): small hand-made files in every format the readers accept, and the
malformed inputs that once crashed, hung or were silently accepted. Run from anywhere; rewrites both
folders. Materials, sessions and truth files come from samples/ and from `ibrdf synth` output when
SYNTH_DIR is given (a session folder written by `ibrdf synth`)."""
import json, os, shutil, struct, sys

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
SEP = b"\n#IBRDF-NEXT-FILE#\n"


def put(kind, target, name, data):
    d = os.path.join(here, kind, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# The regressions are all written here; the corpora also hold what fuzzing grew (merged with
# libFuzzer's -merge=1, files named by their hash), which is kept.
shutil.rmtree(os.path.join(here, "regressions"), ignore_errors=True)

# PLY
tri = ("ply\nformat ascii 1.0\ncomment a triangle\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
put("corpus", "ply", "ascii_triangle.ply", tri)
hdr = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "property float nx\nproperty float ny\nproperty float nz\nproperty float quality\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n").encode()
body = b"".join(struct.pack("<7f", *v) for v in [(0, 0, 0, 0, 0, 1, 1), (1, 0, 0, 0, 0, 1, 0.5), (0, 1, 0, 0, 0, 1, 0.2)])
put("corpus", "ply", "binary_le_normals.ply", hdr + body + struct.pack("<B3i", 3, 0, 1, 2))
hdr = ("ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
       "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n").encode()
put("corpus", "ply", "binary_be_cloud.ply", hdr + struct.pack(">3d3B", 0, 0, 0, 1, 2, 3) + struct.pack(">3d3B", 1, 1, 1, 4, 5, 6))
grid = ("ply\nformat ascii 1.0\nobj_info num_cols 3\nobj_info num_rows 2\nelement vertex 4\nproperty float x\n"
        "property float y\nproperty float z\nelement range_grid 6\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n0.001 0 0\n0 0.001 0\n0.001 0.001 0\n1 0\n1 1\n0\n1 2\n1 3\n0\n")
put("corpus", "ply", "range_grid.ply", grid)
# A 300-byte PLY declaring a 100000 x 20000 range grid (8 GB before reading any data).
put("regressions", "ply", "huge_range_grid.ply",
    "ply\nformat ascii 1.0\nobj_info num_cols 100000\nobj_info num_rows 20000\nelement vertex 1\nproperty float x\n"
    "property float y\nproperty float z\nelement range_grid 2000000000\nproperty list uchar int vertex_indices\n"
    "end_header\n0 0 0\n1 0\n")
put("regressions", "ply", "negative_grid_index.ply", grid.replace("1 1\n0\n1 2", "1 -5\n0\n1 2"))
put("regressions", "ply", "nan_quality.ply",
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 nan\n1 0 0 1\n0 1 0 1\n3 0 1 2\n")
put("regressions", "ply", "nan_vertex.ply", tri.replace("1 0 0\n", "nan 0 0\n"))
put("regressions", "ply", "huge_vertex_count.ply",
    tri.replace("element vertex 3", "element vertex 18446744073709551615"))

# COLMAP: binary and text, three files each.
def colmap_binary(nan=False, bad_counts=False):
    cams = struct.pack("<Q", 1) + struct.pack("<IiQQ", 1, 2, 640, 480) + struct.pack("<4d", 500, 320, 240, 0.01)
    imgs = struct.pack("<Q", 2)
    for i in (1, 2):
        imgs += struct.pack("<I4d3dI", i, 1, 0, 0, 0, 0.1 * i, 0, 1, 1) + b"photo-%d.png\0" % i
        imgs += struct.pack("<Q", 2) + struct.pack("<ddq", 10, 20, 1) + struct.pack("<ddq", 30, 40, -1)
    pts = struct.pack("<Q", 1) + struct.pack("<Q3d3Bd", 1, float("nan") if nan else 0.5, 0.2, 3, 10, 20, 30, 0.7)
    pts += struct.pack("<Q", 2) + struct.pack("<II", 1, 0) + struct.pack("<II", 2, 0)
    if bad_counts:
        imgs = struct.pack("<Q", 6148914691236517206) + imgs[8:]
    return cams + SEP + imgs + SEP + pts
put("corpus", "colmap_binary", "two_images.bin", colmap_binary())
put("regressions", "colmap_binary", "nan_point.bin", colmap_binary(nan=True))
put("regressions", "colmap_binary", "huge_image_count.bin", colmap_binary(bad_counts=True))

cams_txt = "# Camera list\n1 SIMPLE_RADIAL 640 480 500 320 240 0.01\n"
imgs_txt = ("# Image list\n1 1 0 0 0 0.1 0 1 1 photo-1.png\n10 20 1 30 40 -1\n"
            "2 1 0 0 0 0.2 0 1 1 photo-2.png\n10 20 1 30 40 -1\n")
pts_txt = "# 3D point list\n1 0.5 0.2 3 10 20 30 0.7 1 0 2 0\n"
def text_model(c, i, p):
    return (c + "\n#IBRDF-NEXT-FILE#\n" + i + "\n#IBRDF-NEXT-FILE#\n" + p)
put("corpus", "colmap_text", "two_images.txt", text_model(cams_txt, imgs_txt, pts_txt))
put("regressions", "colmap_text", "trailing_garbage_number.txt", text_model(cams_txt, imgs_txt.replace("1 1 0 0 0 0.1", "1 1 0 0 0 12x.5"), pts_txt))
put("regressions", "colmap_text", "fraction_in_int.txt", text_model(cams_txt.replace("1 SIMPLE_RADIAL 640", "1 SIMPLE_RADIAL 0.1"), imgs_txt, pts_txt))
put("regressions", "colmap_text", "extra_field.txt", text_model(cams_txt.replace("0.01\n", "0.01 7\n"), imgs_txt, pts_txt))
put("regressions", "colmap_text", "missing_field.txt", text_model(cams_txt.replace(" 0.01\n", "\n"), imgs_txt, pts_txt))
put("regressions", "colmap_text", "nan_point.txt", text_model(cams_txt, imgs_txt, pts_txt.replace("1 0.5", "1 nan")))
put("regressions", "colmap_text", "stod_overflow.txt", text_model(cams_txt, imgs_txt.replace("0.1 0 1 1", "1e999 0 1 1"), pts_txt))
put("regressions", "colmap_text", "stoll_overflow.txt", text_model(cams_txt, imgs_txt.replace("30 40 -1", "30 40 99999999999999999999999"), pts_txt))

# JSON: materials, truth, sessions.
mats = os.path.join(root, "samples", "materials")
for name in sorted(os.listdir(mats)):
    put("corpus", "material_json", name, open(os.path.join(mats, name), "rb").read())
    put("corpus", "truth_json", name, json.dumps({"format": "ibrdf-truth", "version": 1,
                                                  "material": json.load(open(os.path.join(mats, name)))}))
# SYNTH_DIR: session folders written by `ibrdf synth`, separated by ':' (e.g. a sphere and a --shape
# squash --brackets 2 --light-unknown session, for the mesh, bracket and white-reference blocks).
for k, synth in enumerate(filter(None, os.environ.get("SYNTH_DIR", "").split(":"))):
    put("corpus", "truth_json", "synth-truth-%d.json" % k, open(os.path.join(synth, "truth.json"), "rb").read())
    put("corpus", "session_json", "synth-session-%d.json" % k, open(os.path.join(synth, "session.json"), "rb").read())
for t in ("material_json", "truth_json", "session_json"):
    put("regressions", t, "number_overflow.json", '{"format": 1e400}')
    put("regressions", t, "duplicate_key.json", '{"a": 1, "a": 2}')
    put("regressions", t, "deep.json", "[" * 1000 + "]" * 1000)
    put("regressions", t, "not_json.json", "\x00\xff{")
put("regressions", "material_json", "huge_number.json", '{"model": "lambertian", "albedo": [1e300, 0.5, 0.5]}')
put("regressions", "material_json", "huge_lobe.json",
    '{"model": "lafortune", "diffuse": [0.1, 0.1, 0.1], "lobes": [{"Cxy": [-1, -1, -1], "Cz": [1e300, 1, 1], "n": [10, 10, 10]}]}')

# .npy: sample files and plain arrays.
def npy(descr, shape, data, version=1, header_extra=""):
    dims = ",".join(str(d) for d in shape) + ("," if len(shape) == 1 else "")
    h = "{'descr': %s, 'fortran_order': False, 'shape': (%s), %s}" % (descr, dims, header_extra)
    if version == 1:
        total = 10 + len(h) + 1
        h += " " * ((total + 63) // 64 * 64 - total) + "\n"
        return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(h)) + h.encode() + data
    total = 12 + len(h) + 1
    h += " " * ((total + 63) // 64 * 64 - total) + "\n"
    return b"\x93NUMPY\x02\x00" + struct.pack("<I", len(h)) + h.encode() + data
sample_descr = ("[('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), ('theta_e', '<f4'), "
                "('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), ('image', '<u4'), "
                "('pixel', '<u4', (2,))]")
import math
def sample(wi=(0, 0, 1), wo=(0.6, 0, 0.8), ti=0.0, te=math.acos(0.8), dphi=0.0, brdf=(0.1, 0.2, 0.3), sigma=(0.01,) * 3):
    return struct.pack("<3f3f3f3f3fI2I", *wi, *wo, ti, te, dphi, *brdf, *sigma, 0, 5, 6)
good = sample() + sample(wi=(0.6, 0, 0.8), wo=(0, 0, 1), ti=math.acos(0.8), te=0.0)
put("corpus", "npy", "samples.npy", npy(sample_descr, [2], good))
put("corpus", "npy", "array.npy", npy("'<f8'", [2, 3], struct.pack("<6d", 0.1, 0.2, 0.3, 1.0, 1.1, 0.5)))
put("corpus", "npy", "array_v2.npy", npy("'<f8'", [1, 3], struct.pack("<3d", 0.1, 0.2, 0.3), version=2))
put("regressions", "npy", "shape_overflow.npy", npy("'<f8'", [6148914691236517206, 3], struct.pack("<2d", 1, 2)))
put("regressions", "npy", "v2_header_high_bit.npy", b"\x93NUMPY\x02\x00" + struct.pack("<I", 0x80000010) + b"{}" * 8)
put("regressions", "npy", "duplicate_shape.npy", npy("'<f8'", [1], struct.pack("<d", 1), header_extra="'shape': (2,), "))
put("regressions", "npy", "trailing_garbage.npy", npy("'<f8'", [1, 3], struct.pack("<3d", 1, 2, 3) + b"junk"))
put("regressions", "npy", "short_shape.npy", npy("'<f8'", [1, 3], struct.pack("<2d", 1, 2)))
put("regressions", "npy", "nan_eval_point.npy", npy("'<f8'", [1, 3], struct.pack("<3d", float("nan"), 0, 0)))
put("regressions", "npy", "samples_nan_brdf.npy", npy(sample_descr, [1], sample(brdf=(float("nan"), 0, 0))))
put("regressions", "npy", "samples_inf_wi.npy", npy(sample_descr, [1], sample(wi=(float("inf"), 0, 0))))
put("regressions", "npy", "samples_angle_range.npy", npy(sample_descr, [1], sample(ti=7.0)))
put("regressions", "npy", "samples_long_wi.npy", npy(sample_descr, [1], sample(wi=(0, 0, 1.5))))
put("regressions", "npy", "samples_negative_sigma.npy", npy(sample_descr, [1], sample(sigma=(-1, 0, 0))))
put("regressions", "npy", "samples_negative_brdf.npy", npy(sample_descr, [1], sample(brdf=(-0.5, 0, 0))))

# MERL: a valid table is 4 + 3*90*90*180*8 bytes (11.7 MB): too big for a seed; the seeds exercise the
# header and size checks, the regressions a NaN cell in a full table are written by the unit tests.
put("corpus", "merl", "header_only.binary", struct.pack("<3i", 90, 90, 180))
put("corpus", "merl", "wrong_dims.binary", struct.pack("<3i", 90, 90, 360) + b"\0" * 64)
put("regressions", "merl", "negative_dims.binary", struct.pack("<3i", -90, 90, 180))
put("regressions", "merl", "short.binary", b"\x5a")

# RGL .bsdf tensor files: header "tensor_file\0", version 1.0, field count, then per field
# name length, name, rank, dtype, offset, shape; data at the offsets (core/tensor_file.cc).
def tensor_file(fields, version=(1, 0)):
    header = b"tensor_file\0" + bytes(version) + struct.pack("<I", len(fields))
    size = len(header) + sum(2 + len(n) + 2 + 1 + 8 + 8 * len(shape) for n, _, shape, _ in fields)
    out, blobs, offset = bytearray(header), b"", (size + 7) // 8 * 8
    for name, dtype, shape, data in fields:
        out += struct.pack("<H", len(name)) + name.encode() + struct.pack("<HBQ", len(shape), dtype, offset)
        out += b"".join(struct.pack("<Q", s) for s in shape)
        blobs += data + b"\0" * ((-len(data)) % 8)
        offset += len(data) + (-len(data)) % 8
    return bytes(out) + b"\0" * ((size + 7) // 8 * 8 - size) + blobs


floats = lambda values: struct.pack("<%df" % len(values), *values)
text = b"a small tensor file"
put("corpus", "bsdf", "fields.bsdf",
    tensor_file([("description", 1, [len(text)], text), ("theta_i", 10, [2], floats([0.0, 1.5])),
                 ("phi_i", 10, [1], floats([0.0]))]))
put("corpus", "bsdf", "empty_fields.bsdf", tensor_file([]))
put("regressions", "bsdf", "version_2.bsdf", tensor_file([], version=(2, 0)))
put("regressions", "bsdf", "past_the_end.bsdf", tensor_file([("theta_i", 10, [1 << 40], b"")]))


# The lights file of `ibrdf lights calibrate` and a session's colour_chart block (fuzz/session_splice.h
# reads them inside a valid session).
lights = {"format": "ibrdf-lights", "version": 1, "intensity_reference": "relative: not measured",
          "lights": [{"id": "L1", "kind": "directional", "direction": [0.1, 0.2, 0.97], "intensity": [1, 1, 1]},
                     {"id": "L2", "kind": "point", "position": [0.5, 0.2, 0.8], "intensity": [2, 2, 2.5]}]}
put("corpus", "lights", "two_lights.json", json.dumps(lights, indent=1))
put("corpus", "lights", "point_light.json", json.dumps(
    {"format": "ibrdf-lights", "version": 1, "lights": [{"id": "L1", "kind": "point", "position": [0, 0, 1]}]}))
put("corpus", "lights", "lights_array.json", json.dumps(lights["lights"]))
put("regressions", "lights", "zero_direction.json", json.dumps({"lights": [{"id": "L1", "kind": "directional", "direction": [0, 0, 0], "intensity": [1, 1, 1]}]}))
put("regressions", "lights", "duplicate_id.json", json.dumps({"lights": [lights["lights"][0], lights["lights"][0]]}))
put("regressions", "lights", "negative_intensity.json", json.dumps({"lights": [dict(lights["lights"][0], intensity=[-1, 1, 1])]}))
put("regressions", "lights", "unknown_kind.json", json.dumps({"lights": [{"id": "L1", "kind": "area", "direction": [0, 0, 1], "intensity": [1, 1, 1]}]}))
patch_names = ["dark skin", "light skin", "blue sky", "foliage", "blue flower", "bluish green", "orange",
               "purplish blue", "moderate red", "purple", "yellow green", "orange yellow", "blue", "green", "red",
               "yellow", "magenta", "cyan", "white", "neutral 8", "neutral 6.5", "neutral 5", "neutral 3.5", "black"]
chart = {"chart": "colorchecker_classic_24", "space": "linear_srgb",
         "photos": [{"file": "calibration/colour-chart.png", "exposure_s": 4.59, "gain": 1.0, "light": "L1"}],
         "corners": [[178.6, 166.8], [623.0, 165.9], [623.1, 434.2], [178.6, 433.2]]}
put("corpus", "colour_matrix", "corners.json", json.dumps(chart))
fitted = dict(chart, matrix=[[1.2, -0.1, -0.1], [-0.05, 1.1, -0.05], [0.0, -0.2, 1.2]],
              patches=[{"name": n, "residual": 0.01} for n in patch_names[:23]] + [{"name": "black", "excluded": "too dark"}])
put("corpus", "colour_matrix", "fitted.json", json.dumps(fitted))
put("corpus", "colour_matrix", "xyz.json", json.dumps(dict(chart, space="xyz", matrix=[[0.4, 0.36, 0.18], [0.21, 0.72, 0.07], [0.02, 0.12, 0.95]])))
put("regressions", "colour_matrix", "singular.json", json.dumps(dict(chart, matrix=[[1, 2, 3], [2, 4, 6], [0, 0, 1]])))
put("regressions", "colour_matrix", "patches_without_matrix.json", json.dumps(dict(chart, patches=fitted["patches"])))
put("regressions", "colour_matrix", "negative_residual.json", json.dumps(dict(fitted, patches=[{"name": "dark skin", "residual": -1}])))
put("regressions", "colour_matrix", "no_photos.json", json.dumps(dict(chart, photos=[])))

# Recipes (the fuzz folder holds material.json) and batch configs (it holds s1/session.json and
# r1/recipe.json).
recipe = {"format": "ibrdf-recipe", "version": 1, "name": "r", "description": "d", "paper": "p",
          "material": "material.json", "synth": ["--sample", "sphere", "--photos", "4", "--seed", "1"]}
put("corpus", "recipe", "recipe.json", json.dumps(recipe, indent=1))
put("corpus", "recipe", "minimal.json", json.dumps({"format": "ibrdf-recipe", "version": 1, "name": "m",
                                                    "material": "material.json", "synth": []}))
put("regressions", "recipe", "sets_out.json", json.dumps(dict(recipe, synth=["--out", "x"])))
put("regressions", "recipe", "missing_material.json", json.dumps(dict(recipe, material="absent.json")))
put("regressions", "recipe", "number_arg.json", json.dumps(dict(recipe, synth=["--photos", 4])))
put("regressions", "recipe", "unknown_key.json", json.dumps(dict(recipe, extra=1)))
batch = {"format": "ibrdf-batch", "version": 1, "out": "batch-out",
         "sessions": ["s1", "r1/recipe.json", {"path": "s1", "name": "named", "options": {"stride": 4}}],
         "options": {"stride": 2, "fits": True, "report": False, "check_regression": False, "degree": 1,
                     "radius_h_deg": 3, "radius_d_deg": 6},
         "threads_per_job": 2, "mem_mb_per_job": 4000, "runtime_min_per_job": 60, "compare": ["r"]}
put("corpus", "batch_config", "batch.json", json.dumps(batch, indent=1))
put("corpus", "batch_config", "minimal.json", json.dumps({"format": "ibrdf-batch", "version": 1, "out": "o", "sessions": ["?1"]}))
put("regressions", "batch_config", "duplicate_name.json", json.dumps(dict(batch, sessions=["s1", "s1"])))
put("regressions", "batch_config", "no_match.json", json.dumps(dict(batch, sessions=["nothing*"])))
put("regressions", "batch_config", "bad_name.json", json.dumps(dict(batch, sessions=[{"path": "s1", "name": "a/b"}])))
put("regressions", "batch_config", "zero_threads.json", json.dumps(dict(batch, threads_per_job=0)))
put("regressions", "batch_config", "negative_stride.json", json.dumps(dict(batch, options={"stride": -1})))

# TIFF and DNG headers: a 4 x 2 8-bit grey strip with Make, Model and an EXIF IFD (ExposureTime,
# FNumber, ISO); the DNG adds DNGVersion and a CFA layout for LibRaw.
def tiff(extra_ifd0=(), width=4, height=2, spp=1, bps=8, exif=True):
    entries, blobs = [], []
    def ascii_tag(tag, text):
        entries.append((tag, 2, len(text) + 1, text.encode() + b"\0"))
    pixels = bytes(range(width * height * spp))
    entries += [(256, 3, 1, width), (257, 3, 1, height), (258, 3, 1, bps), (259, 3, 1, 1), (262, 3, 1, 1 if spp == 1 else 2),
                (273, 4, 1, "PIXELS"), (277, 3, 1, spp), (278, 3, 1, height), (279, 4, 1, len(pixels))]
    ascii_tag(271, "ibrdf"); ascii_tag(272, "fuzz camera")
    if exif:
        entries.append((34665, 4, 1, "EXIF"))
    entries += list(extra_ifd0)
    entries.sort(key=lambda e: e[0])
    exif_entries = [(33434, 5, 1, struct.pack("<II", 1, 125)), (33437, 5, 1, struct.pack("<II", 8, 1)), (34855, 3, 1, 200)]
    def ifd_size(n):
        return 2 + 12 * n + 4
    offset = 8 + ifd_size(len(entries))
    data = bytearray()
    def place(blob):
        nonlocal data
        at = offset + len(data)
        data += blob + (b"\0" if len(blob) % 2 else b"")
        return at
    out_entries = []
    sizes = {1: 1, 2: 1, 3: 2, 4: 4, 5: 8, 7: 1}
    pix_at = exif_at = None
    for tag, typ, count, value in entries:
        out_entries.append([tag, typ, count, value])
    pix_at = place(pixels)
    exif_at = offset + len(data)
    exif_blob_base = exif_at + ifd_size(len(exif_entries))
    exif_data = bytearray()
    exif_ifd = struct.pack("<H", len(exif_entries))
    for tag, typ, count, value in exif_entries:
        if isinstance(value, bytes):
            exif_ifd += struct.pack("<HHII", tag, typ, count, exif_blob_base + len(exif_data))
            exif_data += value
        else:
            exif_ifd += struct.pack("<HHIHH", tag, typ, count, value, 0)
    exif_ifd += struct.pack("<I", 0)
    data += exif_ifd + exif_data
    ifd = struct.pack("<H", len(out_entries))
    for tag, typ, count, value in out_entries:
        if value == "PIXELS":
            value = pix_at
        elif value == "EXIF":
            value = exif_at
        if isinstance(value, bytes):
            if len(value) <= 4:
                ifd += struct.pack("<HHI", tag, typ, count) + value.ljust(4, b"\0")
            else:
                ifd += struct.pack("<HHII", tag, typ, count, place(value))
        elif typ == 3:
            ifd += struct.pack("<HHIHH", tag, typ, count, value, 0)
        else:
            ifd += struct.pack("<HHII", tag, typ, count, value)
    ifd += struct.pack("<I", 0)
    return b"II*\0" + struct.pack("<I", 8) + ifd + bytes(data)
put("corpus", "image_header", "grey.tif", tiff())
put("corpus", "image_header", "rgb16.tif", tiff(spp=3, bps=16, exif=False))
put("corpus", "image_header", "cfa.dng", tiff([(50706, 1, 4, bytes([1, 4, 0, 0])), (33421, 3, 2, struct.pack("<HH", 2, 2)),
                                              (33422, 1, 4, bytes([0, 1, 1, 2])), (50708, 2, 5, b"fuzz\0")], width=4, height=2))
put("regressions", "image_header", "truncated.tif", tiff()[:20])
put("regressions", "image_header", "zero_width.tif", tiff(width=0))
print("seeds written under", here)
