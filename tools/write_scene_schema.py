"""Writes scenes/scene.schema.json, the scene format's JSON Schema (engine/formats/scene_schema.py),
for editors that validate and complete scene files, and docs/SCENE_FORMAT.md, its reference
for readers, from the same schema:

    .venv/bin/python tools/write_scene_schema.py
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from engine.formats.output import write_files  # noqa: E402
from engine.formats.scene_schema import reference_text, schema_text  # noqa: E402

if __name__ == "__main__":
    outputs = [(ROOT / "scenes" / "scene.schema.json", schema_text()), (ROOT / "docs" / "SCENE_FORMAT.md", reference_text())]
    write_files([(path, lambda f, text=text: f.write(text.encode())) for path, text in outputs])
    print("wrote " + " and ".join(str(path.relative_to(ROOT)) for path, _ in outputs))
