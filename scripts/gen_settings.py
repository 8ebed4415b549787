#!/usr/bin/env python3
"""Generate asval's layer manifest template, settings X-macro list and sample settings file.

Single source: scripts/settings.json. Outputs (all checked in):
  generated/VkLayer_asval_as_validation.json.in   whole manifest template; CMake fills in @ASVAL_*@
  generated/asval_settings_defs.inc               X-macro list the C++ settings library includes
  vk_layer_settings.txt                           documented example settings file (repository root)

Usage:
  gen_settings.py             rewrite the outputs
  gen_settings.py --verify    exit 1 if any checked-in output differs from what would be generated
Both modes first check settings.json and that the manifest template is valid JSON once its
@VARS@ are substituted, so a broken source never produces (or passes as) good output.
Python 3 standard library only.
"""

import argparse
import difflib
import json
import re
import sys
import textwrap
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
SOURCE = REPO_ROOT / "scripts" / "settings.json"
MANIFEST_OUT = Path("generated") / "VkLayer_asval_as_validation.json.in"
DEFS_OUT = Path("generated") / "asval_settings_defs.inc"
SAMPLE_OUT = Path("vk_layer_settings.txt")

# Values used only to prove the template becomes valid JSON; CMake supplies the real ones.
TEMPLATE_PROBE_VALUES = {
    "ASVAL_LIBRARY_PATH": "./libVkLayer_asval_as_validation.so",
    "ASVAL_API_VERSION": "1.3.239",
    "ASVAL_IMPLEMENTATION_VERSION": "1",
}

SNAKE_CASE = re.compile(r"^[a-z][a-z0-9_]*$")
CPP_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
TEMPLATE_VAR = re.compile(r"@([A-Za-z0-9_]+)@")

# Manifest setting types the C++ side knows how to read, and the X-macro each one becomes.
MACRO_FOR_TYPE = {
    "BOOL": "ASVAL_SETTING_BOOL",
    "INT": "ASVAL_SETTING_INT",
    "STRING": "ASVAL_SETTING_STRING",
    "SAVE_FILE": "ASVAL_SETTING_STRING",
    "LOAD_FILE": "ASVAL_SETTING_STRING",
    "SAVE_FOLDER": "ASVAL_SETTING_STRING",
    "LOAD_FOLDER": "ASVAL_SETTING_STRING",
    "LIST": "ASVAL_SETTING_LIST",
    "FLAGS": "ASVAL_SETTING_FLAGS",
    "ENUM": "ASVAL_SETTING_ENUM",
}
STRING_TYPES = {"STRING", "SAVE_FILE", "LOAD_FILE", "SAVE_FOLDER", "LOAD_FOLDER"}
INT_CPP_TYPES = {"uint32_t": (0, 2**32 - 1), "int32_t": (-(2**31), 2**31 - 1)}


class SourceError(Exception):
    """settings.json breaks a rule the generator relies on."""


# ---------------------------------------------------------------------------------------------
# Naming rules of Vulkan-Utility-Libraries (layer_settings_util.cpp), mirrored by the C++ side.

def trim_prefix(layer_name):
    return layer_name[len("VK_LAYER_"):] if layer_name.startswith("VK_LAYER_") else layer_name


def trim_vendor(layer_name):
    body = trim_prefix(layer_name)
    sep = body.find("_")
    return body if sep < 0 else body[sep + 1:]


def file_key(layer_name, setting):
    return trim_prefix(layer_name).lower() + "." + setting


def env_names(layer_name, setting):
    """Environment variable names in lookup order: TRIM_NONE, TRIM_VENDOR, TRIM_NAMESPACE."""
    up = setting.upper()
    return [
        "VK_" + trim_prefix(layer_name).upper() + "_" + up,
        "VK_" + trim_vendor(layer_name).upper() + "_" + up,
        "VK_" + up,
    ]


# ---------------------------------------------------------------------------------------------
# Source checks

def require(cond, message):
    if not cond:
        raise SourceError(message)


def check_ascii(text, where):
    require(isinstance(text, str), f"{where} must be a string")
    require(all(32 <= ord(c) < 127 for c in text), f"{where} must be printable ASCII: {text!r}")


def check_cpp_name(name, where, seen_cpp_names):
    """A C++ identifier the .inc declares at namespace scope, so it must be unique."""
    require(isinstance(name, str) and CPP_IDENTIFIER.match(name), f"{where} must be a C++ identifier")
    require(name not in seen_cpp_names, f"{where}: C++ name {name} used twice")
    seen_cpp_names.add(name)


def check_flag_list(s, where, seen_cpp_names):
    """The flags array of a FLAGS or ENUM setting (the vkconfig schema uses it for both); its keys."""
    flags = s.get("flags")
    require(isinstance(flags, list) and flags, f"{where}: {s['type']} needs a non-empty flags array")
    flag_keys = set()
    for f in flags:
        fkey = f.get("key")
        require(isinstance(fkey, str) and SNAKE_CASE.match(fkey), f"{where}: flag key {fkey!r} must be snake_case")
        require(fkey not in flag_keys, f"{where}: duplicate flag {fkey}")
        flag_keys.add(fkey)
        for field in ("label", "description"):
            check_ascii(f.get(field), f"{where}.flags.{fkey}.{field}")
        check_cpp_name(f.get("cpp", {}).get("name"), f"{where}: flag {fkey} cpp.name", seen_cpp_names)
    return flag_keys


def check_setting(s, seen_keys, seen_cpp_names):
    key = s.get("key")
    require(isinstance(key, str) and SNAKE_CASE.match(key), f"setting key {key!r} must be snake_case")
    require(key not in seen_keys, f"duplicate setting key {key}")
    seen_keys.add(key)
    where = f"setting {key}"
    for field in ("label", "description"):
        check_ascii(s.get(field), f"{where}.{field}")
    stype = s.get("type")
    require(stype in MACRO_FOR_TYPE, f"{where}: type {stype!r} is not one the C++ side reads "
                                     f"({', '.join(sorted(MACRO_FOR_TYPE))})")
    require("default" in s, f"{where}: needs a default")
    default = s["default"]
    if stype == "BOOL":
        require(isinstance(default, bool), f"{where}: BOOL default must be true or false")
    elif stype == "INT":
        require(isinstance(default, int) and not isinstance(default, bool), f"{where}: INT default must be an integer")
        cpp_type = s.get("cpp", {}).get("type")
        require(cpp_type in INT_CPP_TYPES, f"{where}: cpp.type must be one of {sorted(INT_CPP_TYPES)}")
        lo, hi = int_range(s)
        require(lo <= default <= hi, f"{where}: default {default} is outside [{lo}, {hi}]")
    elif stype in STRING_TYPES:
        check_ascii(default, f"{where}.default")
        require("#" not in default, f"{where}: a '#' cannot be written in a settings file")
    elif stype == "LIST":
        require(isinstance(default, list), f"{where}: LIST default must be an array of strings")
        for item in default:
            check_ascii(item, f"{where}.default item")
            require(item and "," not in item and "#" not in item, f"{where}: list item {item!r} cannot be written in a settings file")
    elif stype == "FLAGS":
        flag_keys = check_flag_list(s, where, seen_cpp_names)
        require(len(flag_keys) <= 32, f"{where}: at most 32 flags fit the uint32_t bitmask")
        require(isinstance(default, list) and all(d in flag_keys for d in default),
                f"{where}: FLAGS default must be an array of its flag keys")
        require(len(set(default)) == len(default), f"{where}: FLAGS default repeats a flag")
    elif stype == "ENUM":
        # The C++ side declares `enum <cpp.type> : uint32_t` with one enumerator per flag, in order.
        check_cpp_name(s.get("cpp", {}).get("type"), f"{where}: cpp.type", seen_cpp_names)
        flag_keys = check_flag_list(s, where, seen_cpp_names)
        require(isinstance(default, str) and default in flag_keys,
                f"{where}: ENUM default must be one of its flag keys")


def check_source(src):
    require(src.get("file_format_version") == "1.2.0", "file_format_version must be 1.2.0")
    layer = src.get("layer")
    require(isinstance(layer, dict), "layer object missing")
    for field in ("name", "type", "library_path", "api_version", "implementation_version", "description"):
        require(isinstance(layer.get(field), str) and layer[field], f"layer.{field} missing")
    require(re.match(r"^VK_LAYER_[A-Z0-9]+_[a-z0-9_]+$", layer["name"]), "layer.name must be VK_LAYER_<ORG>_<words>")
    require("features" not in layer, "layer.features is generated from the settings array; do not write it")
    settings = src.get("settings")
    require(isinstance(settings, list) and settings, "settings array missing")
    seen_keys, seen_cpp_names = set(), set()
    for s in settings:
        check_setting(s, seen_keys, seen_cpp_names)


def int_range(s):
    lo, hi = INT_CPP_TYPES[s["cpp"]["type"]]
    rng = s.get("range", {})
    return max(lo, rng.get("min", lo)), min(hi, rng.get("max", hi))


# ---------------------------------------------------------------------------------------------
# Output 1: manifest template

def strip_cpp(obj):
    """Copy of obj without the C++-only 'cpp' keys (the vkconfig schema forbids unknown keys)."""
    if isinstance(obj, dict):
        return {k: strip_cpp(v) for k, v in obj.items() if k != "cpp"}
    if isinstance(obj, list):
        return [strip_cpp(v) for v in obj]
    return obj


def manifest_setting(s, layer_name):
    # vkconfig schema order: key, label, description, type, then type-specific fields.
    out = {"key": s["key"], "label": s["label"], "description": s["description"], "type": s["type"]}
    out["env"] = env_names(layer_name, s["key"])[0]
    for field in ("flags", "filter", "range"):
        if field in s:
            out[field] = strip_cpp(s[field])
    out["default"] = s["default"]
    return out


def render_manifest(src):
    layer = dict(src["layer"])
    layer["features"] = {"settings": [manifest_setting(s, layer["name"]) for s in src["settings"]]}
    manifest = {"file_format_version": src["file_format_version"], "layer": layer}
    return json.dumps(manifest, indent=4) + "\n"


def check_manifest_template(text, layer_name):
    """The template must become valid JSON with every @VAR@ replaced by a plausible value."""
    unknown = sorted(set(TEMPLATE_VAR.findall(text)) - set(TEMPLATE_PROBE_VALUES))
    require(not unknown, f"manifest template uses variables CMake does not set: {unknown}")
    filled = TEMPLATE_VAR.sub(lambda m: TEMPLATE_PROBE_VALUES[m.group(1)], text)
    try:
        parsed = json.loads(filled)
    except json.JSONDecodeError as e:
        raise SourceError(f"manifest template is not valid JSON after substitution: {e}")
    require(parsed["layer"]["name"] == layer_name, "manifest layer name changed after substitution")
    require(parsed["layer"]["library_path"] == TEMPLATE_PROBE_VALUES["ASVAL_LIBRARY_PATH"],
            "library_path must be exactly @ASVAL_LIBRARY_PATH@")


# ---------------------------------------------------------------------------------------------
# Output 2: X-macro list for C++

def c_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def default_text(s):
    """The default as a settings file or environment variable would spell it."""
    d = s["default"]
    if s["type"] == "BOOL":
        return "true" if d else "false"
    if s["type"] in ("LIST", "FLAGS"):
        return ",".join(d)
    return str(d)


def render_defs(src):
    lines = [
        "// Generated by scripts/gen_settings.py from scripts/settings.json. Do not edit: change the JSON",
        "// and rerun the script (CTest gen_settings_verify fails while this file is stale).",
        "//",
        "// X-macro list of the layer's settings. Define the macros a file needs, then include this file;",
        "// undefined macros expand to nothing and all of them are #undef'd at the end, so the file can be",
        "// included several times. Arguments:",
        "//   ASVAL_SETTINGS_LAYER_NAME(name)                           layer name, a string literal",
        "//   ASVAL_SETTING_FLAG(setting, flag, cpp_name, bit)          one bit of a FLAGS setting; listed",
        "//                                                             before the setting it belongs to",
        "//   ASVAL_SETTING_FLAGS(key, default_bits, default_text)",
        "//   ASVAL_SETTING_INT(key, cpp_type, default_value, min, max, default_text)",
        "//   ASVAL_SETTING_BOOL(key, default_value, default_text)",
        "//   ASVAL_SETTING_STRING(key, default_value, default_text)",
        "//   ASVAL_SETTING_LIST(key, default_value, default_text)",
        "//   ASVAL_SETTING_ENUM_TYPE(cpp_type, cpp_names...)           the C++ type of an ENUM setting and",
        "//                                                             its enumerators, in value order from 0",
        "//   ASVAL_SETTING_ENUM_VALUE(setting, value, cpp_name)        one value of an ENUM setting; listed",
        "//                                                             before the setting it belongs to",
        "//   ASVAL_SETTING_ENUM(key, cpp_type, default_value, default_text)",
        "// key/setting: the snake_case setting name as a bare identifier; flag, value: string literals;",
        "// default_value: a parenthesised C++ expression; default_text: the default spelled the way",
        "// vk_layer_settings.txt spells it. FLAGS and ENUM defaults use the ASVAL_SETTING_FLAG and",
        "// ASVAL_SETTING_ENUM_TYPE cpp_names, so those must be in scope where defaults are expanded.",
        "",
    ]
    macros = (["ASVAL_SETTINGS_LAYER_NAME", "ASVAL_SETTING_FLAG", "ASVAL_SETTING_ENUM_TYPE", "ASVAL_SETTING_ENUM_VALUE"]
              + sorted(set(MACRO_FOR_TYPE.values())))
    for m in macros:
        lines += [f"#ifndef {m}", f"#define {m}(...)", "#endif"]
    lines += ["", f"ASVAL_SETTINGS_LAYER_NAME({c_string(src['layer']['name'])})", ""]
    for s in src["settings"]:
        key, stype, d = s["key"], s["type"], s["default"]
        text = c_string(default_text(s))
        if stype == "FLAGS":
            names = {}
            for bit, f in enumerate(s["flags"]):
                names[f["key"]] = f["cpp"]["name"]
                lines.append(f"ASVAL_SETTING_FLAG({key}, {c_string(f['key'])}, {f['cpp']['name']}, 0x{1 << bit:x}u)")
            bits = " | ".join(names[k] for k in d) if d else "0u"
            lines.append(f"ASVAL_SETTING_FLAGS({key}, ({bits}), {text})")
        elif stype == "ENUM":
            cpp_type, names = s["cpp"]["type"], {f["key"]: f["cpp"]["name"] for f in s["flags"]}
            lines.append(f"ASVAL_SETTING_ENUM_TYPE({cpp_type}, {', '.join(names.values())})")
            for value, cpp_name in names.items():
                lines.append(f"ASVAL_SETTING_ENUM_VALUE({key}, {c_string(value)}, {cpp_name})")
            lines.append(f"ASVAL_SETTING_ENUM({key}, {cpp_type}, ({names[d]}), {text})")
        elif stype == "INT":
            lo, hi = int_range(s)
            lines.append(f"ASVAL_SETTING_INT({key}, {s['cpp']['type']}, ({d}), ({lo}), ({hi}), {text})")
        elif stype == "BOOL":
            lines.append(f"ASVAL_SETTING_BOOL({key}, ({'true' if d else 'false'}), {text})")
        elif stype in STRING_TYPES:
            lines.append(f"ASVAL_SETTING_STRING({key}, (std::string{{{c_string(d)}}}), {text})")
        elif stype == "LIST":
            items = ", ".join(c_string(i) for i in d)
            lines.append(f"ASVAL_SETTING_LIST({key}, (std::vector<std::string>{{{items}}}), {text})")
    lines.append("")
    for m in macros:
        lines.append(f"#undef {m}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------
# Output 3: documented sample settings file (VEL/VVL style)

def comment_block(text, width=100):
    return ["# " + line for line in textwrap.wrap(text, width - 2)]


def render_sample(src):
    layer_name = src["layer"]["name"]
    prefix = trim_prefix(layer_name).lower()
    env = env_names(layer_name, "<setting>")
    out = [
        f"# vk_layer_settings.txt: example settings for {layer_name} (asval).",
        "# Generated by scripts/gen_settings.py from scripts/settings.json; edit the JSON, not this file.",
        "#",
        "# Where the layer looks for a settings file. Only the FIRST file found is read:",
        "#   1. $XDG_DATA_HOME/vulkan/settings.d/vk_layer_settings.txt, or",
        "#      $HOME/.local/share/vulkan/settings.d/vk_layer_settings.txt when XDG_DATA_HOME is unset",
        "#      (the file vkconfig writes; used only if it is a regular file);",
        "#   2. $VK_LAYER_SETTINGS_PATH: a directory gets /vk_layer_settings.txt appended, a file is used",
        "#      as is, a path that does not exist is skipped. A directory without the file still ends the",
        "#      search (nothing is read);",
        "#   3. vk_layer_settings.txt in the current working directory.",
        "#",
        "# Each setting is resolved on its own; the first source that sets it wins:",
        f"#   1. environment variables, upper case, in this order: {env[0]},",
        f"#      {env[1]}, {env[2]} (the first non-empty one counts; note that",
        "#      VK_<SETTING> is shared with every other layer that reads settings this way);",
        "#   2. this file;",
        "#   3. VkLayerSettingsCreateInfoEXT structures in the VkInstanceCreateInfo pNext chain, entries",
        f"#      whose pLayerName is \"{layer_name}\" (first match wins).",
        "# An empty value counts as unset. A malformed value is reported as a warning and the setting",
        "# keeps its default; the next source is not consulted.",
        "#",
        f"# Syntax: {prefix}.<setting> = <value>",
        "# A '#' starts a comment anywhere on a line, even inside a value. Whitespace around keys and",
        "# values is ignored; a later duplicate key replaces an earlier one. Lists and flags:",
        "# comma-separated, or colon-separated when there is no comma. Booleans: true/false, on/off",
        "# (any case) or an integer (non-zero is true). Integers: decimal or 0x hex. Unknown settings",
        "# under the layer's prefix are reported as warnings and ignored. String and path settings are",
        "# taken verbatim (never split at ',' or ':').",
        "#",
        "# Every setting below is commented out and shows its default, so this file changes nothing when",
        "# the layer runs in the repository root. Remove the leading '#' to change a setting.",
    ]
    for s in src["settings"]:
        key = s["key"]
        out += ["", f"# {s['label']}", "# " + "=" * 21, f"# {prefix}.{key}  ({s['type']})"]
        out += comment_block(s["description"])
        if s["type"] == "FLAGS":
            out.append("# Flags:")
            for f in s["flags"]:
                out += comment_block(f"  {f['key']}: {f['description']}")
        if s["type"] == "ENUM":
            out.append("# Values (exactly one):")
            for f in s["flags"]:
                out += comment_block(f"  {f['key']}: {f['description']}")
        if s["type"] == "INT":
            lo, hi = int_range(s)
            out.append(f"# Range: {lo} to {hi}.")
        out += comment_block("Environment: " + ", ".join(env_names(layer_name, key)))
        value = default_text(s)
        out.append(f"#{prefix}.{key} = {value}".rstrip())
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------

def generate(src):
    check_source(src)
    manifest = render_manifest(src)
    check_manifest_template(manifest, src["layer"]["name"])
    return {MANIFEST_OUT: manifest, DEFS_OUT: render_defs(src), SAMPLE_OUT: render_sample(src)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--verify", action="store_true", help="fail if a checked-in output is stale")
    parser.add_argument("--root", type=Path, default=REPO_ROOT, help="repository root (default: this checkout)")
    args = parser.parse_args()
    source = args.root / "scripts" / "settings.json"
    try:
        src = json.loads(source.read_text(encoding="utf-8"))
        outputs = generate(src)
    except (OSError, json.JSONDecodeError, SourceError) as e:
        print(f"gen_settings: {source}: {e}", file=sys.stderr)
        return 2

    stale = []
    for rel, text in outputs.items():
        path = args.root / rel
        current = path.read_text(encoding="utf-8") if path.exists() else None
        if current == text:
            continue
        if args.verify:
            stale.append(rel)
            diff = difflib.unified_diff((current or "").splitlines(True), text.splitlines(True),
                                        f"{rel} (checked in)", f"{rel} (generated)")
            sys.stderr.writelines(list(diff)[:60])
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
            print(f"gen_settings: wrote {rel}")
    if stale:
        print("gen_settings: stale outputs (run scripts/gen_settings.py): " + ", ".join(map(str, stale)),
              file=sys.stderr)
        return 1
    if args.verify:
        print("gen_settings: all outputs up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
