"""Rigid tools: surfaces with a signed gap, a normal and a shape operator at points, a travel
axis (protocol.py), their paths along it (travel.py), and the kinds of tools a scene names
(kinds.py: square, round, cad, channel).

    protocol      the Tool and Binder protocols; a tool's surface mesh for output
    kinds         the registry of kinds: scene keys, checks, factory, output
    square, round, cad, channel    the kinds (channel: a hat channel over a flat or curved binder)
    travel        a tool's path along its axis: linear, or stopping (a holder closing a binder)
    cylinder      a circular cylinder (the binder wrap study's faces)
    analytic      the analytic punch, die and blank holder (signed distances of rounded squares)
    holder_edge   the holder's inner edge in plan: a rounded square or a CAD die's opening
    placement     a tool turned, moved and travelling along its axis
    closest_point the closest-point engine both surface tools share: remembered points, the
                  warm start, the search, the signed pass; each tool supplies its patches
    surface_tool, cad_projections, cad_exact, cad_model, faces, cad_files   a tool from a CAD
                  file's faces (gmsh's OCC kernel)
    mesh_tool, mesh_patches, nagata, mesh_files   a tool from a surface mesh (.stl, .msh:
                  Nagata patches)
    surface_geometry   the Hessian of the distance to a parametrised surface

Below scene, contact, results and nonlinear: it imports none of them.
"""
