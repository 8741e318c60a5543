"""The interactive viewer (`vct view`): a glfw window on engine.Renderer with an ImGui
overlay and panels, a fly camera, GLSL hot reload and screenshots.

Modules: app (Viewer, view_command), window (glfw), gui (ImGui backends), panels (widgets),
inspector (scene edits, no GL), camera (fly camera, no GL), hot_reload, stats, present,
screenshots. The GL-free modules import without a display.
"""
