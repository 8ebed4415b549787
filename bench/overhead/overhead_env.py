"""Configurations (which layers, which settings) and the environment every measured program runs in."""

import os
import re
from dataclasses import dataclass, field
from typing import Dict, List

ASVAL = "VK_LAYER_ASVAL_as_validation"
KHRONOS = "VK_LAYER_KHRONOS_validation"
SYSTEM_LAYER_DIR = "/usr/share/vulkan/explicit_layer.d"
LAVAPIPE_ICD = "/usr/share/vulkan/icd.d/lvp_icd.json"


@dataclass
class Config:
    name: str
    env: Dict[str, str] = field(default_factory=dict)  # VK_INSTANCE_LAYERS and settings


def default_configs() -> List[Config]:
    return [
        Config("none", {}),
        Config("asval", {"VK_INSTANCE_LAYERS": ASVAL}),  # defaults: capture=updates, capture_method=auto
        Config("asval-capture-off", {"VK_INSTANCE_LAYERS": ASVAL, "VK_ASVAL_AS_VALIDATION_CAPTURE": "off"}),
        Config("asval-capture-all", {"VK_INSTANCE_LAYERS": ASVAL, "VK_ASVAL_AS_VALIDATION_CAPTURE": "all"}),
        Config("khronos", {"VK_INSTANCE_LAYERS": KHRONOS}),  # the installed package, default settings
    ]


_ASSIGNMENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*=")


def parse_config(text: str) -> Config:
    """NAME:ENV=VALUE,ENV=VALUE. A comma followed by something that is not ENV= belongs to the value before it
    (enabled_checks=features,handles,...). The asval layer is enabled unless VK_INSTANCE_LAYERS is given."""
    name, sep, rest = text.partition(":")
    if not sep or not name or not rest:
        raise SystemExit(f"--config {text!r}: expected NAME:ENV=VALUE[,ENV=VALUE...]")
    env: Dict[str, str] = {}
    last = None
    for piece in rest.split(","):
        if _ASSIGNMENT.match(piece):
            key, _, value = piece.partition("=")
            env[key] = value
            last = key
        elif last is not None:
            env[last] += "," + piece
        else:
            raise SystemExit(f"--config {text!r}: {piece!r} is not ENV=VALUE")
    env.setdefault("VK_INSTANCE_LAYERS", ASVAL)
    return Config(name, env)


def base_environment(build_dir: str, layer_dir: str) -> Dict[str, str]:
    """The integration tests' environment: lavapipe (unless VK_DRIVER_FILES is set), the real loader, the layer
    from the build tree and the installed Khronos layer, no implicit layers, and a private HOME and XDG folder
    with no settings file, so that no user configuration leaks in. Every other VK_* variable of the caller's
    (layer settings, VK_INSTANCE_LAYERS) is dropped: each configuration names its own."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("VK_")}
    xdg = os.path.join(build_dir, "bench", "overhead", "xdg")
    os.makedirs(xdg, exist_ok=True)
    env.update({
        "VK_LAYER_PATH": f"{layer_dir}:{SYSTEM_LAYER_DIR}",
        "VK_DRIVER_FILES": os.environ.get("VK_DRIVER_FILES", LAVAPIPE_ICD),
        "VK_LOADER_LAYERS_DISABLE": "~implicit~",
        "HOME": xdg,
        "XDG_DATA_HOME": xdg,
        "VK_LAYER_SETTINGS_PATH": os.path.join(xdg, "none"),
    })
    return env


def tolerates_messages(config: Config) -> bool:
    """Whether a run may report messages: only where the Khronos layer is on (its 1.3.239 release reports false
    errors on the scene). asval must report nothing on valid calls, and nothing is there to report without a
    layer."""
    return KHRONOS in config.env.get("VK_INSTANCE_LAYERS", "").split(":")


def environment(base: Dict[str, str], config: Config) -> Dict[str, str]:
    env = dict(base)
    env.update(config.env)
    return env
