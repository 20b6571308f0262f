"""Report sections, one module per chapter section, each with ``build(ctx) -> Section``."""
