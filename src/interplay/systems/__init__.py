"""Separate simulations, each with its own state, integrator and step (the System protocol)."""
