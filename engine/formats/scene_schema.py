"""The scene file format as one declarative JSON Schema (draft 2020-12): every object's fields,
their types, ranges (from engine/core/limits.py) and defaults. `scenes/scene.schema.json` is this
schema as published for editors (tools/write_scene_schema.py writes it; a test keeps the two
equal).

validate() checks a parsed scene file against it with jsonschema and raises SceneError for the
first fault in document order, worded like the loader's other errors: the field's path with
node names (`objects[6] "Short Box".size[0]: must be positive`), and for an unknown or
misspelled key the nearest valid one (`materials.red: unknown field "albeod" (did you mean
"albedo"?)`). What a schema cannot say (a material named but not defined, a degenerate quad,
world transforms) the loader checks after it (engine/formats/scene_file.py)."""
import difflib
import functools
import json

import fastjsonschema
import jsonschema

from ..core.constants import GRID_SIZES, MAX_VOXEL_LEVELS
from ..core.errors import SceneError
from ..core.limits import MAX_EMISSION, MAX_MAGNITUDE, MIN_FOV_DEG, MIN_SCALE

GEOMETRY_TYPES = ("quad", "box", "sphere", "mesh", "group")
LIGHT_TYPES = ("point", "spot", "directional")
NODE_LISTS = ("objects", "lights", "children")  # the lists whose items are nodes


def _number(description, minimum=-MAX_MAGNITUDE, maximum=MAX_MAGNITUDE, positive=False, default=None):
    schema = {"type": "number", "description": description, "maximum": maximum}
    schema.update({"exclusiveMinimum": 0} if positive else {"minimum": minimum})
    if default is not None:
        schema["default"] = default
    return schema


def _vector(description, length=3, minimum=-MAX_MAGNITUDE, maximum=MAX_MAGNITUDE, positive=False, default=None):
    schema = {"type": "array", "description": description, "minItems": length, "maxItems": length,
              "items": _number("a component", minimum, maximum, positive)}
    del schema["items"]["description"]
    if default is not None:
        schema["default"] = default
    return schema


def object_schema(description, properties, required=()):
    """An object of exactly these fields (an unknown one is an error)."""
    schema = {"type": "object", "description": description, "properties": properties, "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    return schema


POSITION = "metres, world space of the node's parent"
MATERIAL = object_schema("A surface's reflectance and emission (engine.scene.model.Material): glTF 2.0's metallic-roughness model", {
    "albedo": _vector("base colour, linear RGB (each at most 1)", minimum=0.0, maximum=1.0, default=[0.8, 0.8, 0.8]),
    "roughness": _number("perceptual roughness r (Blinn-Phong exponent 2/r^4 - 2)", 0.0, 1.0, default=1.0),
    "metalness": _number("0: dielectric, 1: metal (its F0 is the albedo)", 0.0, 1.0, default=0.0),
    "specular": _number("the dielectric's reflectance at normal incidence F0 (glTF: 0.04); 0: Lambert alone",
                        0.0, 1.0, default=0.0),
    "emission": _vector("radiance W/(m^2 sr) of the front side (right-hand rule)", minimum=0.0, maximum=MAX_EMISSION,
                        default=[0.0, 0.0, 0.0]),
    "double_sided": {"type": "boolean", "description": "both sides reflect (a thin sheet); else back faces are culled",
                     "default": False},
})
CAMERA = object_schema("The pinhole camera", {
    "position": _vector(f"eye, {POSITION}"),
    "look_at": _vector("the point looked at"),
    "up": _vector("the image's up direction", default=[0.0, 1.0, 0.0]),
    "vertical_fov_deg": _number("vertical field of view, degrees", MIN_FOV_DEG, 179.0, default=60.0),
    "width": {"type": "integer", "description": "image width in pixels", "exclusiveMinimum": 0, "maximum": MAX_MAGNITUDE,
              "default": 256},
    "height": {"type": "integer", "description": "image height in pixels", "exclusiveMinimum": 0, "maximum": MAX_MAGNITUDE,
               "default": 256},
}, required=("position", "look_at"))
ENVIRONMENT = object_schema("The light from beyond the scene: a uniform sky, or an equirectangular map (engine.scene.model."
                      "Environment: +y up, the map's left edge looking along -z, as Mitsuba's envmap)", {
    "radiance": _vector("a uniform sky's radiance, W/(m^2 sr), linear RGB", minimum=0.0, maximum=MAX_EMISSION),
    "map": {"type": "string", "description": "an equirectangular map of linear radiance, .exr or .hdr, relative to "
                                             "the scene file"},
    "scale": _number("multiplies the radiance or the map", 0.0, MAX_EMISSION, default=1.0),
    "rotation_y_deg": _number("turns the sky about +y, degrees (right-handed)", default=0.0),
})
CLIPMAP = object_schema("Voxel levels centred on the camera, for scenes larger than one grid: level k a cube of "
                  "resolution^3 voxels 2^k voxel_size wide (engine/voxels/clipmap.py)", {
    "levels": {"type": "integer", "description": "how many levels, each twice as large as the one inside it",
               "minimum": 1, "maximum": MAX_VOXEL_LEVELS},
    "resolution": {"enum": list(GRID_SIZES), "description": "voxels per side of each level"},
    "voxel_size": _number("the finest level's voxel side, metres", positive=True),
}, required=("levels", "resolution", "voxel_size"))
VOXEL_REGION = object_schema("Where the voxels lie: the cube one grid spans (center and size; default: the scene's bounds "
                       "padded by 5 %), or a clipmap", {
    "center": _vector(f"the grid's centre, {POSITION}"),
    "size": _number("the grid's side, metres", MIN_SCALE),
    "clipmap": {"$ref": "#/$defs/clipmap", "description": "levels around the camera instead of one grid"},
})

NODE_FIELDS = {
    "name": {"type": "string", "description": "the node's name in the scene graph"},
    "type": {"enum": list(GEOMETRY_TYPES + LIGHT_TYPES), "description": "what the node is"},
    "translation": _vector("T of the local transform T R S, metres", default=[0.0, 0.0, 0.0]),
    "rotation": _vector("R: degrees about x, then y, then z", default=[0.0, 0.0, 0.0]),
    "scale": _vector("S, per axis", positive=True, default=[1.0, 1.0, 1.0]),
    "children": {"type": "array", "description": "nodes placed by this one", "items": {"$ref": "#/$defs/node"}},
}
SURFACE = {"material": {"type": "string", "description": "the name of one of the scene's materials"}}
INTENSITY = _vector("radiant intensity, W/sr", minimum=0.0)
SHADOWS = {"cast_shadows": {"type": "boolean", "description": "whether the light casts shadows", "default": True}}
RANGE = {"range": _number("distance where the light fades to zero; 0: inverse square without a cut-off", 0.0, default=0.0)}
DIRECTION = _vector("the direction the light travels (not zero)")
NODE_TYPES = {
    "quad": ("A quadrilateral, its normal by the right-hand rule of its vertices", dict(SURFACE, vertices={
        "type": "array", "description": "4 vertices, metres", "minItems": 4, "maxItems": 4, "items": _vector("a vertex")}),
        ("material", "vertices")),
    "box": ("An axis-aligned box turned about y", dict(
        SURFACE, center=_vector("its centre, metres", default=[0.0, 0.0, 0.0]),
        size=_vector("its sides, metres", positive=True), rotation_y_deg=_number("degrees about y", default=0.0)),
        ("material", "size")),
    "sphere": ("A sphere", dict(SURFACE, center=_vector("its centre, metres", default=[0.0, 0.0, 0.0]),
                                radius=_number("metres", positive=True)), ("material", "radius")),
    "mesh": ("The nodes of a mesh file: glTF/GLB, OBJ+MTL, PLY, STL or OFF", dict(
        file={"type": "string", "description": "the file, relative to the scene file"},
        material={"type": "string", "description": "a scene material for every part; without it the parts keep "
                                                   "the file's materials"}), ("file",)),
    "group": ("A transform for its children", {}, ()),
    "point": ("A point light", dict(position=_vector("metres", default=[0.0, 0.0, 0.0]), intensity=INTENSITY,
                                    **RANGE, **SHADOWS), ("intensity",)),
    "spot": ("A spot light", dict(
        position=_vector("metres", default=[0.0, 0.0, 0.0]), direction=DIRECTION, intensity=INTENSITY,
        outer_angle_deg=_number("half-angle of the cone, degrees (no light outside)", maximum=89.0, positive=True,
                                default=45.0),
        inner_angle_deg=_number("half-angle of full intensity, degrees (at most outer_angle_deg; default 0.8 of it)",
                                0.0, 89.0), **RANGE, **SHADOWS), ("direction", "intensity")),
    "directional": ("A directional light (the sun)", dict(
        direction=DIRECTION, irradiance=_vector("irradiance on a surface facing it, W/m^2", minimum=0.0), **SHADOWS),
        ("direction", "irradiance")),
}


def _node(types):
    """A node of one of `types`: its `type` picks the fields it takes."""
    return {"type": "object", "required": ["type"], "properties": {"type": dict(NODE_FIELDS["type"], enum=list(types))},
            "allOf": [{"if": {"properties": {"type": {"const": kind}}, "required": ["type"]},
                       "then": object_schema(NODE_TYPES[kind][0], dict(NODE_FIELDS, **NODE_TYPES[kind][1]), NODE_TYPES[kind][2])}
                      for kind in types]}


SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "vct scene",
    **object_schema("A scene for vct, the voxel cone tracing renderer. Units are metres, right-handed, +y up.", {
        "$schema": {"type": "string", "description": "this schema, for editors"},
        "name": {"type": "string", "description": "the scene's name (default: the file's stem)"},
        "about": {"type": "string", "description": "what the scene is, for its readers"},
        "camera": {"$ref": "#/$defs/camera", "description": "the camera (default: the first camera of the mesh files, "
                                                           "else one framing the scene)"},
        "materials": {"type": "object", "description": "materials by name", "additionalProperties": {"$ref": "#/$defs/material"}},
        "objects": {"type": "array", "description": "the scene's nodes", "items": {"$ref": "#/$defs/node"}},
        "lights": {"type": "array", "description": "the scene's lights (given, the mesh files' lights are left out)",
                   "items": {"$ref": "#/$defs/light"}},
        "voxel_region": {"$ref": "#/$defs/voxel_region"},
        "environment": {"$ref": "#/$defs/environment"},
    }),
    "$defs": {"camera": CAMERA, "material": MATERIAL, "voxel_region": VOXEL_REGION, "clipmap": CLIPMAP,
              "environment": ENVIRONMENT,
              "node": _node(GEOMETRY_TYPES + LIGHT_TYPES), "light": _node(LIGHT_TYPES)},
}
_VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)
# The same checks a node at a time, so that a scene of thousands of nodes is checked in a
# fraction of a second (the whole schema weighs every node against every type): the scene
# without its nodes, and each node by its type, its children left to the walk. A node passes
# through fastjsonschema's compiled check of its type's schema (draft-07 keywords alone, read
# alike by both); one that fails it, or has no type of its list, is checked by jsonschema,
# whose errors name the field.
_ANY_NODE = {"type": "array"}
_SCENE_VALIDATOR = jsonschema.Draft202012Validator(dict(SCHEMA, properties=dict(SCHEMA["properties"], objects=_ANY_NODE,
                                                                                 lights=_ANY_NODE)))
_TYPE_SCHEMAS = {kind: object_schema(NODE_TYPES[kind][0], dict(NODE_FIELDS, children=_ANY_NODE, **NODE_TYPES[kind][1]),
                               NODE_TYPES[kind][2]) for kind in NODE_TYPES}
_TYPE_VALIDATORS = {kind: jsonschema.Draft202012Validator(schema) for kind, schema in _TYPE_SCHEMAS.items()}
_LIST_VALIDATORS = {types: jsonschema.Draft202012Validator(_node(types)) for types in (GEOMETRY_TYPES + LIGHT_TYPES, LIGHT_TYPES)}


@functools.lru_cache(maxsize=None)
def _type_check(kind):
    """fastjsonschema's compiled check of a node type's schema (made at its first use)."""
    return fastjsonschema.compile(dict(_TYPE_SCHEMAS[kind], **{"$schema": "http://json-schema.org/draft-07/schema#"}))


def _passes(kind, node):
    try:
        _type_check(kind)(node)
        return True
    except fastjsonschema.JsonSchemaException:
        return False


def default(definition, field):
    """The default of a field of an object of the schema: default("material", "roughness")."""
    if definition in NODE_TYPES:
        properties = dict(NODE_FIELDS, **NODE_TYPES[definition][1])
    else:
        properties = SCHEMA["$defs"][definition]["properties"]
    return properties[field]["default"]


def validate(document, source):
    """Raise SceneError for the first fault of the parsed scene `document` in document order
    (the faults _VALIDATOR finds, found a node at a time)."""
    try:
        errors = list(_SCENE_VALIDATOR.iter_errors(document))
        if isinstance(document, dict):
            for key, types in (("objects", GEOMETRY_TYPES + LIGHT_TYPES), ("lights", LIGHT_TYPES)):
                if isinstance(document.get(key), list):
                    errors += _node_errors(document[key], [key], types)
    except RecursionError:
        raise SceneError("nested too deeply", source=source) from None
    if errors:
        field, message = _earliest(document, errors)
        raise SceneError(message, source=source, field=field)


def first_fault(validator, document):
    """(field, message) of the first fault `validator` finds in `document`, in document order
    and in the loader's words; None where it finds none."""
    errors = list(validator.iter_errors(document))
    return _earliest(document, errors) if errors else None


def _earliest(document, errors):
    """(field, message) of the fault of `errors` that comes first in `document`."""
    return _describe(document, min(errors, key=lambda e: _document_order(document, e)))


def _node_errors(nodes, path, types):
    """The faults of a list of nodes (at `path`) of `types`, their children's included, with
    their paths from the document's root."""
    errors = []
    for index, node in enumerate(nodes):
        kind = node.get("type") if isinstance(node, dict) else None
        typed = isinstance(kind, str) and kind in types
        if not typed or not _passes(kind, node):
            validator = _TYPE_VALIDATORS[kind] if typed else _LIST_VALIDATORS[types]
            for error in validator.iter_errors(node):
                error.path.extendleft(reversed([*path, index]))
                errors.append(error)
        if typed and isinstance(node.get("children"), list):
            errors += _node_errors(node["children"], [*path, index, "children"], GEOMETRY_TYPES + LIGHT_TYPES)
    return errors


def _document_order(document, error):
    """Where an error stands in the document: the position of each key or index along its path."""
    order, value = [], document
    for key in error.absolute_path:
        order.append(list(value).index(key) if isinstance(value, dict) else key)
        value = value[key]
    return order


def _field(document, path):
    """The loader's name of a path: `objects[6] "Short Box".size[0]`."""
    field, value, parent = "", document, None
    for key in path:
        if isinstance(key, int):
            field += f"[{key}]"
            value = value[key]
            if parent in NODE_LISTS and isinstance(value, dict) and isinstance(value.get("name"), str):
                field += f' "{value["name"]}"'
        else:
            field += f".{key}" if field else str(key)
            value = value[key]
        parent = key
    return field


NOUNS = {"number": "a number", "integer": "a whole number", "string": "a string", "object": "an object",
         "boolean": "true or false", "array": "a list"}


def _describe(document, error):
    """(field, message) of a jsonschema error, in the loader's words."""
    path = list(error.absolute_path)
    field = _field(document, path)
    kind, expected, schema, instance = error.validator, error.validator_value, error.schema, error.instance
    if kind == "additionalProperties":
        known = list(schema.get("properties", {}))
        unknown = next(key for key in instance if key not in known)
        near = difflib.get_close_matches(unknown, known, n=1, cutoff=0.6) or [
            key for key in known if unknown.lower() in key.lower()]
        return field, f'unknown field "{unknown}"' + (f' (did you mean "{near[0]}"?)' if near else "")
    if kind == "required":
        missing = next(key for key in expected if key not in instance)
        return f"{field}.{missing}" if field else missing, "missing"
    if kind in ("minItems", "maxItems") or (kind == "type" and "minItems" in schema):
        items = schema.get("items", {})
        noun = "numbers" if items.get("type") == "number" else str(path[-1]) if path else "items"
        return field, f"must {'be a list of' if noun == 'numbers' else 'hold'} {schema['minItems']} {noun}"
    if kind == "type":
        return field, f"must be {NOUNS[expected]}"
    if kind == "minimum":
        return field, "must not be negative" if expected == 0 else f"must be at least {expected:g}"
    if kind == "exclusiveMinimum":
        return field, "must be positive" if expected == 0 else f"must be more than {expected:g}"
    if kind == "maximum":
        return field, f"must be at most {expected:g}"
    if kind == "enum" and path and path[-1] == "type":
        return field, f'unknown type "{instance}" (expected one of {", ".join(expected)})'
    if kind == "enum":
        return field, f"must be one of {', '.join(map(str, expected))}"
    return field, error.message



def schema_text():
    """The schema as published: JSON, one key a line."""
    return json.dumps(SCHEMA, indent=1) + "\n"


def reference_text():
    """The format's reference for readers, docs/SCENE_FORMAT.md, generated from the schema:
    each object's fields with their type, range, default and meaning."""
    lines = ["# The scene format", "", SCHEMA["description"], "",
             "Generated from `engine/formats/scene_schema.py` by `tools/write_scene_schema.py`, as is",
             "`scenes/scene.schema.json` (the same format as a JSON Schema, for editors); a test keeps both",
             "up to date. A field the format does not define is an error naming it and the nearest valid",
             "one; the loader checks what a schema cannot say (materials named but not defined, degenerate",
             "quads, world transforms: engine/formats/scene_file.py).", ""]
    lines += _reference_table("The scene file", SCHEMA["properties"], SCHEMA.get("required", ()))
    for name in ("camera", "material", "environment", "voxel_region", "clipmap"):
        definition = SCHEMA["$defs"][name]
        lines += _reference_table(f"`{name}`: {definition['description']}", definition["properties"],
                                  definition.get("required", ()))
    lines += _reference_table("Every node (`objects`, `lights`, `children`)", NODE_FIELDS, ("type",))
    for kind, (description, fields, required) in NODE_TYPES.items():
        lines += _reference_table(f'`"type": "{kind}"`: {description}', fields, required)
    return "\n".join(lines)


def _reference_table(title, properties, required):
    rows = [f"## {title}", "", "| field | type | range | default | meaning |", "|---|---|---|---|---|"]
    for field, spec in properties.items():
        if field == "$schema":
            continue
        name = f"`{field}`" + (" (required)" if field in required else "")
        default = f"`{json.dumps(spec['default'])}`" if "default" in spec else ""
        meaning = spec.get("description") or SCHEMA["$defs"][spec["$ref"].rsplit("/", 1)[1]]["description"]
        rows.append(f"| {name} | {_reference_type(spec)} | {_reference_range(spec)} | {default} | {meaning} |")
    return rows + [""]


def _reference_type(spec):
    if "$ref" in spec:
        return f"object: `{spec['$ref'].rsplit('/', 1)[1]}`"
    if "enum" in spec:
        return " \\| ".join(f"`{value}`" for value in spec["enum"])
    kind = spec.get("type")
    if kind == "array":
        items = spec["items"]
        count = f"{spec['minItems']} × " if "minItems" in spec and spec["minItems"] == spec.get("maxItems") else "list of "
        return count + (_reference_type(items) if "type" in items or "$ref" in items else "nodes")
    if kind == "object" and "additionalProperties" in spec:
        return f"name → {_reference_type(spec['additionalProperties'])}"
    return kind


def _reference_range(spec):
    spec = spec.get("items", spec) if spec.get("type") == "array" else spec
    low = f"> {spec['exclusiveMinimum']:g}" if "exclusiveMinimum" in spec else None
    low = low or (f"{spec['minimum']:g}" if "minimum" in spec and spec["minimum"] > -MAX_MAGNITUDE else None)
    high = f"{spec['maximum']:g}" if "maximum" in spec and spec["maximum"] < MAX_MAGNITUDE else None
    if low and high:
        return f"{low[2:]} < v ≤ {high}" if low.startswith(">") else f"{low}..{high}"
    if low:
        return low if low.startswith(">") else f"≥ {low}"
    return f"≤ {high}" if high else ""
