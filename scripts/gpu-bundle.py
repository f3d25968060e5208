#!/usr/bin/env python3
"""Pack a built Radiant for a GPU machine that has none of its Debian packages (issue 31's GPU check).

The device machines lent to this project run a CUDA image with CMake and ninja but without Radiant's
packages, and nothing can be installed there. So the GPU check's binaries are built here and carried:
this script writes one archive holding stripped copies of the gl/http test executables and the
programs they start (radiantd, radiant, fake_radiantd) at their build-tree paths, the build tree's
CTest files, the test data that lives beside the checkout (../shared/testdata), the programs the
client runs (gnuplot), and the shared libraries they all load.

OpenImageIO links about 200 libraries for image formats Radiant never reads or writes (video, DICOM,
OpenVDB, camera raw, HEIF, JPEG 2000, GIF, OpenCV): those are replaced by stubs with the same soname
and versioned symbols whose functions return at once, which cuts the libraries from ~410 MB to what
one call can carry. Radiant reads PNG/JPEG/WebP/KTX2/HDR/EXR and writes PNG/EXR, whose OpenImageIO
plugins use the real libraries; of the stubs only the version-string functions are called. glibc, libstdc++ and libgcc_s are the
device's own (newer than Debian 12's); the GL vendor-neutral dispatch (libglvnd) is carried, the
vendor driver is the device's.

Usage: scripts/gpu-bundle.py [--build build] [--out .gpu/bundle.tar.xz]
On the device: scripts/gpu-check.sh --bundle .gpu/bundle.tar.xz (it unpacks, links the paths the
build tree was made at, and runs the check on what it unpacked; docs/PERFORMANCE.md, "GPU check").
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

# Libraries OpenImageIO needs for formats Radiant does not use (see the docstring).
STUBBED = [
    "libopencv_core.so.406", "libopencv_imgproc.so.406", "libopencv_videoio.so.406",
    "libdcmimage.so.17", "libdcmimgle.so.17", "libdcmdata.so.17", "liboflog.so.17", "libofstd.so.17",
    "libavcodec.so.59", "libavformat.so.59", "libavutil.so.57", "libswscale.so.6",
    "libgif.so.7", "libheif.so.1", "libopenjp2.so.7", "libopenvdb.so.10.0", "libraw_r.so.20",
]
# The device's own: glibc and the GCC runtime (the device image is newer than Debian 12).
SYSTEM = re.compile(r"^(libc|libm|libdl|libpthread|librt|libresolv|libutil|ld-linux-x86-64|libstdc\+\+|libgcc_s)\.so")
# Loaded with dlopen by libepoxy, so ldd does not list them.
GLVND = ["libEGL.so.1", "libOpenGL.so.0", "libGL.so.1", "libGLX.so.0", "libGLdispatch.so.0"]
LIBDIR = "/lib/x86_64-linux-gnu"
TOOLS = ["gnuplot"]


def sh(*args, **kw):
    return subprocess.run(args, check=True, capture_output=True, text=True, **kw).stdout


def dynsyms(path):
    """(defined, undefined) dynamic symbols of an ELF file: readelf's fields, the name keeping its version."""
    defined, undefined = [], set()
    for line in sh("readelf", "--dyn-syms", "-W", path).splitlines():
        f = line.split()
        if len(f) < 8 or not f[0].endswith(":") or f[6] in ("ABS", "Ndx"):
            continue
        if f[6] == "UND":
            undefined.add(f[7].split("@")[0])
        else:
            defined.append(f)
    return defined, undefined


def make_stub(real, outdir, tmp, wanted=None):
    """A shared library with real's soname and the symbols it defines (same version), doing nothing
    (each function returns a pointer to 256 zero bytes).
    With wanted, only the symbols named there: C++ libraries also export vague-linkage copies (vtables,
    typeinfo, template instances) that other libraries bind to, and a zero-filled copy of those breaks
    them (llvmpipe's JIT called a null vtable slot before this filter)."""
    name = os.path.basename(real)
    syms = []
    for f in dynsyms(real)[0]:
        if wanted is not None and f[7].split("@")[0] not in wanted:
            continue
        typ, bind, full = f[3], f[4], f[7]
        try:
            size = int(f[2], 0)
        except ValueError:
            size = 8
        if typ not in ("FUNC", "IFUNC", "OBJECT", "TLS", "NOTYPE"):
            continue
        m = re.match(r"^([^@]+)(@@?)?(.*)$", full)
        syms.append((m.group(1), m.group(2) or "", m.group(3), typ, bind, max(size, 8)))
    versions = sorted({v for _, at, v, *_ in syms if at})
    # Functions return a pointer to zeros: OpenImageIO formats the version strings of its format
    # libraries (opj_version(), heif_get_version()...) when it lists them, and a null one asserts.
    asm = [".section .rodata", ".balign 16", "radiant_stub_zeros: .zero 256"]
    for i, (sym, at, ver, typ, bind, size) in enumerate(syms):
        local = f"radiant_stub_{i}" if at else sym
        vis = ".weak" if bind == "WEAK" else ".globl"
        if typ in ("FUNC", "IFUNC", "NOTYPE"):
            asm += [".text", f"{vis} {local}", f".type {local},@function", f"{local}: lea radiant_stub_zeros(%rip),%rax", "ret"]
        elif typ == "TLS":
            asm += [".section .tbss,\"awT\",@nobits", f"{vis} {local}", f".type {local},@tls_object",
                    f".size {local},{size}", f"{local}: .zero {size}"]
        else:
            asm += [".data", ".balign 16", f"{vis} {local}", f".type {local},@object", f".size {local},{size}",
                    f"{local}: .zero {size}"]
        if at:
            asm.append(f".symver {local},{sym}{at}{ver}")
    src = os.path.join(tmp, name + ".s")
    with open(src, "w") as fh:
        fh.write("\n".join(asm) + "\n.section .note.GNU-stack,\"\",@progbits\n")
    cmd = ["cc", "-shared", "-nostdlib", "-o", os.path.join(outdir, name), f"-Wl,-soname,{name}", src]
    if versions:
        vs = os.path.join(tmp, name + ".map")
        with open(vs, "w") as fh:
            fh.write("".join(f"{v} {{ }};\n" for v in versions))
        cmd.insert(-1, f"-Wl,--version-script={vs}")
    subprocess.run(cmd, check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default=".gpu/bundle.tar.xz")
    ap.add_argument("--labels", default="gl|http", help="ctest labels whose executables are packed")
    a = ap.parse_args()
    root = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
    build = os.path.abspath(os.path.join(root, a.build))
    shared = os.path.abspath(os.path.join(root, "..", "shared", "testdata"))
    tests = json.loads(sh("ctest", "--test-dir", build, "-L", a.labels, "--show-only=json-v1"))["tests"]
    exes = sorted({t["command"][0] for t in tests if t.get("command")})
    # And the executables they start by their build-tree path (radiantd, radiant, fake_radiantd...).
    named = set()
    pattern = re.compile(re.escape(build.encode()) + rb"/[A-Za-z0-9_/.+-]+")
    for exe in exes:
        with open(exe, "rb") as fh:
            named |= {m.decode() for m in pattern.findall(fh.read())}
    exes += sorted(p for p in named if os.path.isfile(p) and os.access(p, os.X_OK) and p not in exes)
    with tempfile.TemporaryDirectory() as tmp:
        stage = os.path.join(tmp, "stage")
        libdir = os.path.join(stage, "lib")
        os.makedirs(libdir)
        for lib in STUBBED:
            make_stub(os.path.join(LIBDIR, lib), libdir, tmp)
        env = dict(os.environ, LD_LIBRARY_PATH=libdir)
        libs = set(os.path.join(LIBDIR, g) for g in GLVND)
        # Programs the client runs (radiant's reports plot with gnuplot), into bin/.
        tools = [os.path.realpath(shutil.which(t)) for t in TOOLS if shutil.which(t)]
        os.makedirs(os.path.join(stage, "bin"))
        for tool, name in zip(tools, [t for t in TOOLS if shutil.which(t)]):
            shutil.copy2(tool, os.path.join(stage, "bin", name))
        for exe in exes + tools:
            for line in sh("ldd", exe, env=env).splitlines():
                m = re.match(r"\s*(\S+) => (/\S+)", line)
                if m and not SYSTEM.match(m.group(1)) and not m.group(2).startswith(libdir):
                    libs.add(m.group(2))
        for lib in sorted(libs):
            shutil.copy2(os.path.realpath(lib), os.path.join(libdir, os.path.basename(lib)))
        # Now that the closure is known, stub only what it imports and nothing else defines.
        needed, provided = set(), set()
        system = [os.path.join(LIBDIR, s) for s in ("libc.so.6", "libm.so.6", "libstdc++.so.6", "libgcc_s.so.1")]
        for f in list(libs) + exes + system:
            d, u = dynsyms(f)
            needed |= u
            provided |= {x[7].split("@")[0] for x in d}
        for lib in STUBBED:
            make_stub(os.path.join(LIBDIR, lib), libdir, tmp, needed - provided)
        for exe in exes:
            dst = os.path.join(stage, "build", os.path.relpath(exe, build))
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            subprocess.run(["strip", "-o", dst, exe], check=True)
        for d, _, files in os.walk(build):
            if os.path.relpath(d, build).split(os.sep)[0] in ("CMakeFiles", "_deps"):
                continue
            for f in files:
                if f == "CTestTestfile.cmake" or f.endswith("_include.cmake") or f.endswith("_tests.cmake"):
                    dst = os.path.join(stage, "build", os.path.relpath(os.path.join(d, f), build))
                    os.makedirs(os.path.dirname(dst), exist_ok=True)
                    shutil.copy2(os.path.join(d, f), dst)
        shutil.copytree(shared, os.path.join(stage, "shared", "testdata"))
        with open(os.path.join(stage, "paths.json"), "w") as fh:
            json.dump({"root": root, "build": build, "shared": os.path.dirname(shared)}, fh)
        os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
        subprocess.run(["tar", "-C", stage, "-cf", os.path.abspath(a.out), "-I", "xz -T2 -6", "."], check=True)
    print(f"{a.out}: {os.path.getsize(a.out) / 2**20:.1f} MiB, {len(exes)} executables, {len(libs)} libraries "
          f"+ {len(STUBBED)} stubs")


if __name__ == "__main__":
    sys.exit(main())
