"""Rules for `reedtool validate`: one module per family, one registry, one runner.

    registry.py       the rule catalogue and the @rule decorator
    finding.py        Issue (what a rule yields) and Finding (what users see)
    context.py        per-run cache of the tree, poses, rotors, mass properties and trim
    runner.py         selection (select/ignore/severity) and execution
    structure.py      S1xx  the URDF tree and what Gazebo's URDF->SDF conversion does
    inertia_rules.py  I2xx  masses and inertia tensors
    rotor_rules.py    R3xx  motor plugins, allocation and hover trim
"""
