"""The PEP 517 build backend of kinetic's Python module, with the standard library only.

`pip install .` calls build_wheel(): CMake configures the project with KINETIC_BUILD_PYTHON=ON
for the interpreter that runs pip (sys.executable), builds the extension `kinetic._kinetic`
(Release, in build/python of the source tree, or $KINETIC_PYTHON_BUILD_DIR; later builds are
incremental), and the package (python/kinetic and the extension) is zipped into a wheel. No
build requirement is downloaded: the build works offline with Debian's cmake, g++, GMP,
pybind11 and numpy (scripts/install-deps.sh installs them).
"""

import base64
import hashlib
import os
import re
import subprocess
import sys
import sysconfig
import tarfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAME = "kinetic"
SUMMARY = "Kinetic data structures over moving objects (robust out-of-order event processing)"


def _version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(kinetic VERSION ([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("kinetic_build: no version in CMakeLists.txt")
    return match.group(1)


def _tag():
    interpreter = "cp%d%d" % sys.version_info[:2]
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return interpreter, interpreter, platform


def _dist_info():
    return "%s-%s.dist-info" % (NAME, _version())


def _metadata():
    return (
        "Metadata-Version: 2.1\n"
        "Name: %s\n"
        "Version: %s\n"
        "Summary: %s\n"
        "License: see the project's repository\n"
        "Requires-Python: >=3.10\n"
        "Requires-Dist: numpy\n" % (NAME, _version(), SUMMARY)
    )


def _wheel_file():
    return (
        "Wheel-Version: 1.0\n"
        "Generator: kinetic_build\n"
        "Root-Is-Purelib: false\n"
        "Tag: %s-%s-%s\n" % _tag()
    )


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    path = os.path.join(metadata_directory, _dist_info())
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata())
    with open(os.path.join(path, "WHEEL"), "w", encoding="utf-8") as f:
        f.write(_wheel_file())
    return _dist_info()


def _run(command):
    print("kinetic_build: " + " ".join(command), flush=True)
    try:
        subprocess.run(command, cwd=ROOT, check=True)
    except FileNotFoundError:
        raise RuntimeError(
            "kinetic_build: %s not found; run scripts/install-deps.sh first" % command[0]
        ) from None


def _build_extension():
    build_dir = os.environ.get("KINETIC_PYTHON_BUILD_DIR", os.path.join(ROOT, "build", "python"))
    jobs = str(os.cpu_count() or 1)
    _run(
        [
            "cmake", "-S", ROOT, "-B", build_dir,
            "-DCMAKE_BUILD_TYPE=Release",
            "-DKINETIC_BUILD_PYTHON=ON",
            "-DKINETIC_BUILD_TOOLS=OFF",
            "-DKINETIC_BUILD_TESTS=OFF",
            "-DKINETIC_BUILD_BENCHMARKS=OFF",
            # A user's compiler may warn where ours does not: warnings do not stop an install.
            "-DKINETIC_WARNINGS_AS_ERRORS=OFF",
            "-DPython_EXECUTABLE=" + sys.executable,
        ]
    )
    _run(["cmake", "--build", build_dir, "--target", "_kinetic", "-j", jobs])
    package = os.path.join(build_dir, "python", NAME)
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    if not os.path.exists(os.path.join(package, "_kinetic" + suffix)):
        raise RuntimeError("kinetic_build: the build made no _kinetic%s in %s" % (suffix, package))
    return package, suffix


def _record_line(arcname, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return "%s,sha256=%s,%d" % (arcname, digest, len(data))


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package, suffix = _build_extension()
    files = []
    sources = os.path.join(ROOT, "python", NAME)  # the package's Python files, as they are now
    for name in sorted(os.listdir(sources)):
        if name.endswith(".py"):
            with open(os.path.join(sources, name), "rb") as f:
                files.append(("%s/%s" % (NAME, name), f.read()))
    with open(os.path.join(package, "_kinetic" + suffix), "rb") as f:
        files.append(("%s/_kinetic%s" % (NAME, suffix), f.read()))
    dist_info = _dist_info()
    files.append((dist_info + "/METADATA", _metadata().encode()))
    files.append((dist_info + "/WHEEL", _wheel_file().encode()))
    files.append((dist_info + "/top_level.txt", (NAME + "\n").encode()))
    record = [_record_line(arcname, data) for arcname, data in files]
    record.append(dist_info + "/RECORD,,")
    files.append((dist_info + "/RECORD", ("\n".join(record) + "\n").encode()))
    wheel_name = "%s-%s-%s-%s-%s.whl" % ((NAME, _version()) + _tag())
    os.makedirs(wheel_directory, exist_ok=True)
    with zipfile.ZipFile(os.path.join(wheel_directory, wheel_name), "w", zipfile.ZIP_DEFLATED) as z:
        for arcname, data in files:
            info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if arcname.endswith(suffix) else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
    return wheel_name


def build_sdist(sdist_directory, config_settings=None):
    """The sources a build needs (the library, the module, the build files), as a .tar.gz."""
    base = "%s-%s" % (NAME, _version())
    parts = ["CMakeLists.txt", "pyproject.toml", "README.md", "cmake", "include", "src", "python"]
    os.makedirs(sdist_directory, exist_ok=True)
    name = base + ".tar.gz"
    with tarfile.open(os.path.join(sdist_directory, name), "w:gz") as tar:
        for part in parts:
            tar.add(
                os.path.join(ROOT, part),
                arcname=base + "/" + part,
                filter=lambda t: None if "__pycache__" in t.name else t,
            )
        pkg_info = os.path.join(sdist_directory, "PKG-INFO")
        with open(pkg_info, "w", encoding="utf-8") as f:
            f.write(_metadata())
        tar.add(pkg_info, arcname=base + "/PKG-INFO")
        os.remove(pkg_info)
    return name


