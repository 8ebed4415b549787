"""What the figures were measured on: the JSON's "machine" object and the baseline's system key."""

import glob
import json
import os
import platform
import re
import subprocess
from typing import Dict, Optional


def _run(argv) -> str:
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        return ""


def os_release() -> Dict[str, str]:
    values = {}
    try:
        with open("/etc/os-release") as f:
            for line in f:
                key, sep, value = line.strip().partition("=")
                if sep:
                    values[key] = value.strip('"')
    except OSError:
        pass
    return values


def cmake_cache(build_dir: str) -> Dict[str, str]:
    values = {}
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt")) as f:
            for line in f:
                m = re.match(r"^([A-Za-z0-9_]+):[A-Z]+=(.*)$", line.strip())
                if m:
                    values[m.group(1)] = m.group(2)
    except OSError:
        pass
    return values


def compiler(build_dir: str) -> str:
    cache = cmake_cache(build_dir)
    cxx = cache.get("CMAKE_CXX_COMPILER", "c++")
    first = _run([cxx, "--version"]).splitlines()
    build_type = cache.get("CMAKE_BUILD_TYPE", "")
    return (first[0] if first else cxx) + (f", {build_type}" if build_type else "")


def compiler_identity(build_dir: str) -> Dict[str, str]:
    """CMAKE_CXX_COMPILER_ID and _VERSION as CMake found them (CMakeFiles/<version>/CMakeCXXCompiler.cmake)."""
    found = {}
    for path in sorted(glob.glob(os.path.join(build_dir, "CMakeFiles", "*", "CMakeCXXCompiler.cmake"))):
        with open(path) as f:
            for line in f:
                m = re.match(r'^set\((CMAKE_CXX_COMPILER_(?:ID|VERSION)) "(.*)"\)$', line.strip())
                if m:
                    found[m.group(1)] = m.group(2)
    return found


def system_key(build_dir: str) -> str:
    """e.g. debian12-gcc12: the OS and the compiler family and major version the layer was built with (the
    instructions the layer executes depend on both)."""
    rel = os_release()
    ident = compiler_identity(build_dir)
    family = {"GNU": "gcc", "Clang": "clang"}.get(ident.get("CMAKE_CXX_COMPILER_ID", ""), "cc")
    version = ident.get("CMAKE_CXX_COMPILER_VERSION", "0")
    return f"{rel.get('ID', 'unknown')}{rel.get('VERSION_ID', '')}-{family}{version.split('.')[0]}"


def build_type(build_dir: str) -> str:
    return cmake_cache(build_dir).get("CMAKE_BUILD_TYPE", "")


def cpu() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def loader() -> str:
    out = _run(["dpkg-query", "-W", "-f", "${Version}", "libvulkan1"]).strip()
    if out:
        return f"libvulkan1 {out}"
    m = re.search(r"Vulkan Instance Version: (\S+)", _run(["vulkaninfo", "--summary"]))
    return f"Vulkan loader {m.group(1)}" if m else "unknown"


def khronos_layer(layer_dir: str) -> str:
    package = _run(["dpkg-query", "-W", "-f", "${Version}", "vulkan-validationlayers"]).strip()
    try:
        with open(os.path.join(layer_dir, "VkLayer_khronos_validation.json")) as f:
            layer = json.load(f)["layer"]
        manifest = f"api {layer.get('api_version')}, implementation {layer.get('implementation_version')}"
    except (OSError, ValueError, KeyError):
        manifest = "manifest not found"
    return f"vulkan-validationlayers {package} ({manifest})" if package else manifest


def machine(build_dir: str, layer_dir: str, driver: Optional[str]) -> Dict[str, object]:
    rel = os_release()
    return {
        "cpu": cpu(),
        "cores": os.cpu_count(),
        "os": f"{rel.get('PRETTY_NAME', platform.system())}, kernel {platform.release()}",
        "compiler": compiler(build_dir),
        "driver": driver or "unknown",
        "loader": loader(),
        "khronos_layer": khronos_layer(layer_dir),
    }
