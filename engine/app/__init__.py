"""The applications, thin clients of engine.Renderer: the `vct` command line (render, view,
bench), the benchmark and the interactive viewer."""
