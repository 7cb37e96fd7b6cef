r"""Model extensions: new mount models built from existing ones, leaving those unchanged.

:func:`with_base_compliance` puts a base node of mass :math:`m_b` under a mount's network,
tied to ground by :math:`c_b` and :math:`d_b` (a compliant chassis; Kovarik 2016, sec. 4.5).
"""

from __future__ import annotations

from powertrain.models.mount import MountModel, Topology

#: Parameter names of the base node (first letter = kind, as in every topology).
BASE_MASS = "m_base"
BASE_STIFFNESS = "c_base"
BASE_DAMPING = "d_base"


def with_base_compliance(mount_model: MountModel, mass: float, stiffness: float,
                         damping: float) -> MountModel:
    r"""A copy of a mount model on a compliant base: elements ending at ``G`` end at a new node
    carrying ``mass``, joined to ``G`` by ``stiffness`` and ``damping``.

    Parameters
    ----------
    mount_model : MountModel
        Network on a rigid base.
    mass : float
        Base (chassis) mass at the mount [kg], > 0.
    stiffness : float
        Base stiffness to ground [N/m], > 0.
    damping : float
        Base damping to ground [N·s/m], >= 0.

    Returns
    -------
    MountModel
        Topology ``"<name>+base"`` with ``m_base``, ``c_base``, ``d_base``.
    """
    if not (mass > 0 and stiffness > 0 and damping >= 0):
        raise ValueError("need base mass > 0, stiffness > 0, damping >= 0")
    topo = mount_model.topology
    if any(p in topo.parameters for p in (BASE_MASS, BASE_STIFFNESS, BASE_DAMPING)):
        raise ValueError(f"{topo.name} already has a compliant base")
    base = f"n{topo.n_internal + 1}"
    elements = tuple((base if a == "G" else a, base if b == "G" else b, c, d)
                     for a, b, c, d in topo.elements)
    elements += ((base, "G", BASE_STIFFNESS, BASE_DAMPING),)
    new_topo = Topology(name=f"{topo.name}+base",
                        description=f"{topo.description} on a compliant base",
                        parameters=topo.parameters + (BASE_MASS, BASE_STIFFNESS, BASE_DAMPING),
                        masses=topo.masses + (BASE_MASS,), elements=elements)
    params = {**mount_model.params, BASE_MASS: float(mass), BASE_STIFFNESS: float(stiffness),
              BASE_DAMPING: float(damping)}
    notes = (mount_model.notes + " " if mount_model.notes else "") + (
        f"on a compliant base: m_base={mass:g} kg, c_base={stiffness:g} N/m, "
        f"d_base={damping:g} N*s/m")
    return MountModel(new_topo, params, name=mount_model.name, source=mount_model.source,
                      notes=notes)
