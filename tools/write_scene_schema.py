"""Writes scenes/scene.schema.json, the scene format's JSON Schema (engine/scene_schema.py),
for editors that validate and complete scene files:

    .venv/bin/python tools/write_scene_schema.py
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from engine.output import write_files  # noqa: E402
from engine.scene_schema import schema_text  # noqa: E402

if __name__ == "__main__":
    path = ROOT / "scenes" / "scene.schema.json"
    write_files([(path, lambda f: f.write(schema_text().encode()))])
    print(f"wrote {path.relative_to(ROOT)}")
