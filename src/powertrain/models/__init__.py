"""Thin model objects over the physics functions: mounts, engine, powertrain."""
from powertrain.models.mount import MountModel, Topology, TOPOLOGIES, DEFAULT_TOPOLOGY

__all__ = ["MountModel", "Topology", "TOPOLOGIES", "DEFAULT_TOPOLOGY"]
