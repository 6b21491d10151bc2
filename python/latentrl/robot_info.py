"""What a URDF holds, as the physics sees it: joints (type, limits, effort, mimic coupling),
links, which collision shape was made from what, total mass. `latentrl urdf-info ROBOT.urdf`
prints it; run it first on a new robot (docs/robots.md)."""

from __future__ import annotations

import math
from os import PathLike
from typing import Any

from latentrl import _native


def urdf_info(path: str | PathLike[str], *, balance_inertia: bool = False) -> dict[str, Any]:
    """Reads and checks the URDF at `path` (meshes hulled, as a task would load it) and returns
    `{name, joints, links, collision, visual, total_mass, warnings}` (see `_native.urdf_info`).
    With `balance_inertia`, inertias the physics cannot take are repaired instead of refused;
    `warnings` lists every repair made (docs/robots.md)."""
    return _native.urdf_info(path, balance_inertia=balance_inertia)


def _limits(joint: dict[str, Any]) -> str:
    if math.isinf(joint["lower"]):
        return "unlimited"
    return f"[{joint['lower']:.4g}, {joint['upper']:.4g}]"


def _optional(value: float | None) -> str:
    return "-" if value is None else f"{value:.4g}"


def _made_from(shape: dict[str, Any]) -> str:
    if shape["hull"] is None:
        return f"{shape['kind']} " + " ".join(f"{v:.4g}" for v in shape["size"])
    hull = shape["hull"]
    cached = ", cached" if hull["cached"] else ""
    return f"convex hull of {hull['vertices']} vertices from {hull['triangles']} triangles in {shape['file']}{cached}"


def format_info(info: dict[str, Any]) -> str:
    """`urdf_info`'s result as the text `latentrl urdf-info` prints."""
    lines = [f"robot {info['name']}: {len(info['links'])} links, total mass {info['total_mass']:.4g} kg", "",
             "joints (actuated in posture order, then mimic):"]
    lines.append(f"  {'name':<24} {'type':<11} {'limits':<22} {'effort':>8} {'velocity':>9}  coupling")
    for j in info["joints"]:
        m = j["mimic"]
        coupling = "-" if m is None else f"= {m['multiplier']:g} * {m['leader']} + {m['offset']:g}"
        lines.append(f"  {j['name']:<24} {j['type']:<11} {_limits(j):<22} {_optional(j['effort']):>8} "
                     f"{_optional(j['velocity']):>9}  {coupling}")
    lines += ["", "collision shapes (what the physics collides):"]
    lines += [f"  {s['link']:<24} {_made_from(s)}" for s in info["collision"]] or ["  none"]
    bodiless = sorted(set(info["links"]) - {s["link"] for s in info["collision"]})
    if bodiless:
        lines.append(f"  links without collision shapes: {', '.join(bodiless)}")
    lines += ["", f"visual shapes: {len(info['visual'])} (drawn, not simulated)"]
    if info["warnings"]:
        lines += ["", "repaired while loading:"] + [f"  {w}" for w in info["warnings"]]
    return "\n".join(lines)
