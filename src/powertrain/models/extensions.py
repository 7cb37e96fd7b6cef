r"""Model extensions: new mount models built from existing ones, leaving those unchanged.

:func:`with_base_compliance` puts a flexible chassis under a mount: the network's ground
(``G``) becomes a base node of mass :math:`m_b` tied to the rigid ground by a spring
:math:`c_b` and a damper :math:`d_b`. The thesis names a rigid chassis as one reason for its
simulation-measurement gaps (Kovarik 2016, sec. 4.5: "chassis is considered as rigid, but in
reality chassis has some compliance"). With a base the force "to ground" of the assembled
model is the force in the base spring and damper.
"""

from __future__ import annotations

from powertrain.models.mount import MountModel, Topology

#: Parameter names of the base node (first letter = kind, as in every topology).
BASE_MASS = "m_base"
BASE_STIFFNESS = "c_base"
BASE_DAMPING = "d_base"


def with_base_compliance(mount_model: MountModel, mass: float, stiffness: float,
                         damping: float) -> MountModel:
    r"""A copy of a mount model standing on a compliant base instead of the rigid ground.

    Every element of the network that ends at ``G`` ends at a new internal node ``n{k+1}``
    (``k`` = internal nodes of the original) instead; that node carries ``mass`` and is joined
    to ``G`` by a Kelvin-Voigt element (``stiffness``, ``damping``). As the base stiffness
    tends to infinity the original model is recovered. The original model is not modified.

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
        Topology ``"<name>+base"`` with the extra parameters ``m_base``, ``c_base``,
        ``d_base``.
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
