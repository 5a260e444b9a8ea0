from myproj.projection import mirrored, project


def test_project(wirecheck):
    wirecheck(project)


def test_mirrored(wirecheck):
    wirecheck(mirrored, cases=["on_axis", "oblique_roll"])
