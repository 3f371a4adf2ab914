"""The cell file format, described from the schema itself: the JSON Schema (``cellstress schema``) and the
field reference in docs/cell-format.md (``cellstress schema --markdown``; a test fails when the two drift).

Every field's meaning is the docstring under it in its record (pydantic's attribute docstrings), its type,
default and range come from its annotation, and the device and criterion kinds are whatever the registries
hold, so a plug-in's record is documented the same way as ours.
"""

from __future__ import annotations

import json
from typing import Any

from cellstress.cell.schema import CellSpec

SCHEMA_ID = "https://cellstress.invalid/cell.schema.json"
INTRO = """\
# Cell file format

A cell file is a YAML document (YAML 1.2: `1e-3` is a number, `yes` is text) describing one robot cell. Units:
metres, degrees, seconds; +z is up; the built-in cells put the robot near the origin, the upper (front) end of
the cell at +y. `cellstress check FILE` validates a file and runs the static ISO 13855 check; a mistake gives
exit code 2 and one line naming the file, the field and the problem. Unknown fields are errors (a misspelt
field must not be silently ignored), `true` is not a number and `"1.5"` is not a number.

`cellstress schema` prints the same format as a JSON Schema, for editors that validate and complete YAML
(the yaml-language-server reads a first line `# yaml-language-server: $schema=cell.schema.json` after
`cellstress schema > cell.schema.json`). The built-in cells (`cellstress cells`) are examples of every field;
docs/cells.md explains their numbers.

This page is generated from the schema (`cellstress schema --markdown`); the device and criterion kinds are
those installed (plug-ins add theirs: docs/extending.md).

## Robots and their programs

`robot.urdf` is a short name of example-robot-data (`cellstress cells` lists them: ur3, ur5, ur10, panda, kinova,
xarm7, ...) or a URDF file: any serial chain of revolute, continuous and prismatic joints, fixed joints and
`<mimic>` joints included. Joint values are degrees, or metres for a prismatic joint. A program gives one value
per *driven* joint: every joint but the `<mimic>` ones (they follow their master) and those in `robot.hold`.
Every value is checked against the URDF's position limits, and a trajectory file also against its velocity
limits. `cellstress new NAME --robot panda` writes a starter cell.
The program takes one of three forms:

```yaml
robot:
  urdf: panda
  hold: [{joint: panda_finger_joint1, value: 0.02}]   # fingers 4 cm apart; finger 2 mimics finger 1
  task:
    # (a) joint waypoints, minimum-jerk moves; optionally a speed and a dwell per move
    waypoints_deg: [[0, -20, 0, -120, 0, 100, 45], [60, -20, 0, -120, 0, 100, 45]]
    speed_scales: [0.5, 0.2]
    dwells: [0.5, 0.2]
    # (b) or tool poses in the cell's frame, solved by inverse kinematics when the cell is loaded
    # tool_frame: panda_hand
    # ik_seed_deg: [0, -45, 0, -135, 0, 90, 45]   # the home the first pose is solved nearest (docs/programs.md)
    # poses:
    #   - {xyz: [-0.55, 0.45, 1.05], rpy_deg: [180, 0, 0]}
    #   - {xyz: [0.55, 0.45, 1.05], rpy_deg: [180, 0, 0]}
    # (c) or a joint-trajectory file (relative to the cell file), played linearly at its own timing:
    # trajectory_csv: pick.csv      # header time,q1,...,q7 (or the joint names); radians unless csv_degrees
```
"""


def json_schema() -> dict[str, Any]:
    """The JSON Schema of a cell file (draft 2020-12, as pydantic writes it), with its title and id."""
    schema = CellSpec.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$id"] = SCHEMA_ID
    schema["title"] = "cellstress cell file"
    return schema


def markdown() -> str:
    """docs/cell-format.md: one section per record, a table of its fields."""
    schema = json_schema()
    defs = schema["$defs"]
    out = [INTRO]
    order = ["CellSpec", *_reachable(schema, defs)]
    for name in order:
        record = schema if name == "CellSpec" else defs[name]
        out.append(f"## {_title(name, record)}\n")
        if record.get("description"):
            out.append(" ".join(record["description"].split()) + "\n")
        out.append("| field | type | default | range | meaning |")
        out.append("|---|---|---|---|---|")
        required = set(record.get("required", ()))
        for field, prop in record.get("properties", {}).items():
            default = ("required" if field in required else _value(prop["default"]) if "default" in prop
                       else "see meaning")
            out.append(f"| `{field}` | {_type(prop)} | {default} | {_range(prop)} | "
                       f"{_cell(prop.get('description', ''))} |")
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def _reachable(schema: dict, defs: dict) -> list[str]:
    """The records in the order a reader meets them: depth first from the cell's fields."""
    seen: list[str] = []

    def visit(node: Any) -> None:
        if isinstance(node, dict):
            ref = node.get("$ref")
            if ref:
                name = ref.rsplit("/", 1)[-1]
                if name not in seen:
                    seen.append(name)
                    visit(defs[name].get("properties", {}))
            for key, value in node.items():
                if key not in ("$ref", "default"):
                    visit(value)
        elif isinstance(node, list):
            for value in node:
                visit(value)

    visit(schema.get("properties", {}))
    return seen


def _title(name: str, record: dict) -> str:
    tag = record.get("properties", {}).get("type", {}).get("const")
    return f"{name} (`type: {tag}`)" if tag else name


def _type(prop: dict) -> str:
    if "$ref" in prop:
        name = prop["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{name.lower()})"
    if "const" in prop:
        return f"`{prop['const']}`"
    if "enum" in prop:
        return " or ".join(f"`{v}`" for v in prop["enum"])
    for key in ("oneOf", "anyOf"):
        if key in prop:
            kinds = [_type(p) for p in prop[key]]
            return " or ".join(dict.fromkeys(kinds))
    kind = prop.get("type")
    if kind == "array":
        if "prefixItems" in prop:
            return "[" + ", ".join(_type(p) for p in prop["prefixItems"]) + "]"
        return f"list of {_type(prop.get('items', {}))}"
    return {"number": "number", "integer": "whole number", "string": "text", "boolean": "true/false",
            "null": "null", "object": "mapping"}.get(kind, "any")


def _range(prop: dict) -> str:
    parts = []
    lo = prop.get("minimum", prop.get("exclusiveMinimum"))
    hi = prop.get("maximum", prop.get("exclusiveMaximum"))
    if lo is not None or hi is not None:
        left = "" if lo is None else f"{_num(lo)} {'<' if 'exclusiveMinimum' in prop else '≤'} "
        right = "" if hi is None else f" {'<' if 'exclusiveMaximum' in prop else '≤'} {_num(hi)}"
        parts.append(f"{left}x{right}")
    if "minItems" in prop or "maxItems" in prop:
        if "prefixItems" not in prop:
            parts.append(f"{prop.get('minItems', 0)}–{prop.get('maxItems', '…')} items")
    if "maxLength" in prop:
        parts.append(f"{prop.get('minLength', 0)}–{prop['maxLength']} characters")
    for key in ("oneOf", "anyOf"):
        for sub in prop.get(key, ()):
            inner = _range(sub)
            if inner:
                parts.append(inner)
    if prop.get("type") == "array" and "items" in prop:
        inner = _range(prop["items"])
        if inner:
            parts.append(f"each {inner}")
    if "prefixItems" in prop:
        inner = {_range(p) for p in prop["prefixItems"]} - {""}
        if len(inner) == 1:
            parts.append(f"each {inner.pop()}")
    return "; ".join(dict.fromkeys(parts))


def _num(x: float) -> str:
    return f"{x:g}"


def _value(v: Any) -> str:
    if v is None:
        return "none"
    return f"`{json.dumps(v, separators=(', ', ': '))}`"


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")
