"""One module per render pass; each owns its GL resources and releases them."""
