"""Thin model objects over the physics functions: mounts, engine, powertrain."""
from powertrain.models.mount import DEFAULT_TOPOLOGY, TOPOLOGIES, MountModel, Topology

__all__ = ["MountModel", "Topology", "TOPOLOGIES", "DEFAULT_TOPOLOGY"]
