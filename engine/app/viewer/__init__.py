"""The interactive viewer (`vct view`): a glfw window on engine.Renderer with an ImGui
overlay and panels, a fly camera, GLSL hot reload and screenshots.

Modules: app (Viewer), window (glfw), gui (ImGui backends), panels (widgets), layout (where
the image and the panels go, no GL), inspector (scene edits, no GL), camera (fly camera, no
GL), playback (animation clock, no GL), hot_reload, stats, present, screenshots. The GL-free
modules import without a display.
"""
