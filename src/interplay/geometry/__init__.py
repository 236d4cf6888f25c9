"""Mesh and network builders."""
