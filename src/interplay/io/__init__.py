"""Files an animator opens, written atomically."""
