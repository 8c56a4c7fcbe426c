"""``python -m graspexp prepare``: what it could not prepare is named, and the exit status says so."""

import trimesh

from graspexp.tools.prepare import main as prepare_main


def test_prepare_names_the_objects_it_could_not_prepare(tmp_path, capsys):
    trimesh.creation.box(extents=(0.05, 0.04, 0.06)).export(tmp_path / "cube.obj")
    trimesh.creation.box(extents=(120.0, 40.0, 60.0)).export(tmp_path / "part.stl")  # millimetres
    assert prepare_main(["dataset=folder", f"dataset.root={tmp_path}", "progress=false"]) == 1
    out, err = capsys.readouterr()
    assert "1 collision shapes of folder ready" in out
    assert "graspexp prepare: part: NOT prepared: mesh " in err and "units:" in err
