"""Mesh files: the data model, the formats, welding and tag lists."""
