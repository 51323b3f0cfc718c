"""CAD parts: B-rep files (STEP, IGES) read through OpenCASCADE (the ``OCP`` bindings).

Owns:
    - :mod:`planner.cad.occt_read`: the file checks (not a STEP/IGES file, truncated), the
      length unit the file declares, its bodies (solids, named by their product) and the
      explicit choice of one (:class:`CadFile`, :func:`read_cad_file`);
    - :mod:`planner.cad.tessellate`: one body's triangulation at a stated chord tolerance,
      with the B-rep face each triangle comes from and which B-rep faces are planes;
    - :mod:`planner.cad.part`: the whole load, cached on disk by the file's hash
      (:func:`load_cad_mesh`, what :func:`planner.cell.scene.load_work_object` calls for a
      ``.step``/``.stp``/``.iges``/``.igs`` file).

The triangles keep their B-rep plane in ``mesh.face_attributes[BREP_PLANE]``
(:data:`planner.faces.brep.BREP_PLANE`); :func:`planner.faces.detection.find_planar_faces` takes
the planar faces from it instead of clustering triangles. ``OCP`` is imported only when a CAD
file is read and not cached. ``docs/step.md`` has the choice of library, the tolerances and why.
"""
