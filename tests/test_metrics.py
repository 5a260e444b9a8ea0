"""oracles.judge.metrics against hand-counted images and hand-derived errors."""

import numpy as np
import pytest
from wirecheck.oracles.judge.metrics import diff_image, pixel_scores, vertex_errors


def test_vertex_errors_hand_values():
    # errors 3-4-5 triangle (5 px) and 0; one point clipped by each side
    cand = np.array([[3.0, 4.0], [10.0, 10.0], [np.nan, np.nan], [1.0, 1.0]])
    orac = np.array([[0.0, 0.0], [10.0, 10.0], [5.0, 5.0], [np.nan, np.nan]])
    ve = vertex_errors(cand, orac)
    assert ve["max_px"] == 5.0 and ve["worst_index"] == 0
    assert ve["mean_px"] == 2.5
    assert ve["rms_px"] == pytest.approx(np.sqrt(12.5), rel=1e-15)  # sqrt((25 + 0) / 2)
    assert (ve["visible_both"], ve["candidate_only"], ve["oracle_only"]) == (2, 1, 1)


def test_pixel_scores_shifted_line():
    # a 10-px horizontal line vs the same line one row down: nothing matches
    # exactly, everything matches within 1 px (Chebyshev)
    a = np.zeros((8, 12), bool)
    a[3, 1:11] = True
    b = np.zeros((8, 12), bool)
    b[4, 1:11] = True
    s = pixel_scores(a, b)
    assert s["f1_0px"] == 0.0
    assert s["f1_1px"] == 1.0


def test_pixel_scores_partial():
    # candidate draws 10 px, oracle 8 of them plus 2 elsewhere (far away):
    # P@0 = 8/10, R@0 = 8/10 -> F1 = 0.8
    a = np.zeros((20, 20), bool)
    a[2, 0:10] = True
    b = np.zeros((20, 20), bool)
    b[2, 0:8] = True
    b[15, 15:17] = True
    s = pixel_scores(a, b)
    assert s["precision_0px"] == 0.8 and s["recall_0px"] == 0.8
    assert s["f1_0px"] == pytest.approx(0.8, abs=1e-15)
    # at 1 px: a's pixels 8, 9 are within 1 of b's pixel 7? only pixel 8 is -> P = 9/10;
    # b's far pixels are unmatched -> R = 8/10
    assert s["precision_1px"] == 0.9 and s["recall_1px"] == 0.8


def test_pixel_scores_blank_images():
    z = np.zeros((4, 4), bool)
    one = z.copy()
    one[1, 1] = True
    assert pixel_scores(z, z)["f1_0px"] == 1.0  # both blank: agree
    assert pixel_scores(one, z)["f1_1px"] == 0.0  # one blank: disagree
    assert pixel_scores(z, one)["f1_1px"] == 0.0


def test_diff_image_colours():
    a = np.array([[1, 1, 0, 0]], bool)
    b = np.array([[1, 0, 1, 0]], bool)
    d = diff_image(a, b)
    assert d[0, 0].tolist() == [255, 255, 255]  # both
    assert d[0, 1].tolist() == [255, 70, 70]  # candidate only: red
    assert d[0, 2].tolist() == [60, 170, 255]  # oracle only: blue
    assert d[0, 3].tolist() == [0, 0, 0]


def test_face_disagreements_on_a_boundary_are_allowed_inside_are_not():
    # Oracle: face 0 on columns 0-4, face 1 on 5-9 of a 6x10 image, depth 1 everywhere.
    from wirecheck.oracles.judge.metrics import shaded_scores

    of = np.zeros((6, 10), int)
    of[:, 5:] = 1
    depth = np.ones((6, 10))
    covered = np.ones((6, 10), bool)
    # Candidate puts the boundary one column later: column 5 disagrees, but face 0
    # is next to it in the oracle's image: a boundary decision, allowed.
    cf = np.zeros((6, 10), int)
    cf[:, 6:] = 1
    s = shaded_scores(depth, covered, depth, cand_faces=cf, oracle_faces=of)
    assert (s["face_disagreements"], s["face_disagreements_inside"]) == (6, 0)
    # Candidate shows face 0 on a 3x3 block (rows 1-3, columns 6-8) inside face 1's
    # region. Its rim touches face 1 in the candidate's own image (like a 1-px
    # sliver of a face seen edge-on would), but its centre (2, 7) has no neighbour
    # showing the other's face in either image: one visibility error.
    cf = of.copy()
    cf[1:4, 6:9] = 0
    s = shaded_scores(depth, covered, depth, cand_faces=cf, oracle_faces=of)
    assert (s["face_disagreements"], s["face_disagreements_inside"]) == (9, 1)


def test_silhouette_mismatch_inside_counts_holes_not_boundary_shifts():
    # Oracle covers a 6x6 block; the candidate covers it shifted right by one column:
    # the mismatched columns are on each silhouette's boundary: 0 inside. A 1-px hole
    # in the candidate's middle is inside the oracle's silhouette: 1.
    from wirecheck.oracles.judge.metrics import shaded_scores

    orac = np.zeros((10, 12), bool)
    orac[2:8, 2:8] = True
    cand = np.zeros((10, 12), bool)
    cand[2:8, 3:9] = True
    depth = np.where(cand, 1.0, np.inf)
    s = shaded_scores(depth, orac, np.ones((10, 12)))
    assert s["silhouette_mismatch_inside"] == 0 and s["silhouette_union_px"] == 42
    hole = np.where(orac, 1.0, np.inf)
    hole[4, 4] = np.inf
    s = shaded_scores(hole, orac, np.ones((10, 12)))
    assert s["silhouette_mismatch_inside"] == 1


def test_occlusion_boundary_marks_both_sides_of_triangles_sharing_no_vertex():
    # triangle 1 (vertices 3, 4, 5) left of triangle 0 (vertices 0, 1, 2): no shared
    # vertex, so depth may jump between columns 1 and 2; both pixels are marked.
    # Triangle 0 is id 0: an id test must count 0 as a triangle (-1 is "none").
    from wirecheck.oracles.judge.metrics import occlusion_boundary

    tris = np.array([[0, 1, 2], [3, 4, 5]])
    ids = np.array([[1, 1, 0, 0]])
    assert occlusion_boundary(ids, tris).tolist() == [[False, True, True, False]]
    shared = np.array([[0, 1, 2], [2, 3, 4]])  # sharing vertex 2: depth is continuous
    assert not occlusion_boundary(ids, shared).any()
    assert not occlusion_boundary(np.array([[-1, 0, 0, -1]]), tris).any()  # -1: no triangle


def _naive_occlusion_boundary(ids, triangles):
    """The definition pixel by pixel: a pixel showing a triangle is marked when one of its 8 neighbours (in the
    image) shows another triangle with no vertex in common with its own."""
    h, w = ids.shape
    corners = [set(t) for t in np.asarray(triangles).tolist()]
    out = np.zeros((h, w), bool)
    for y in range(h):
        for x in range(w):
            a = ids[y, x]
            for yy in range(max(y - 1, 0), min(y + 2, h)):
                for xx in range(max(x - 1, 0), min(x + 2, w)):
                    b = ids[yy, xx]
                    if a >= 0 and b >= 0 and a != b and not corners[a] & corners[b]:
                        out[y, x] = True
    return out


def test_occlusion_boundary_equals_the_definition_on_random_id_images():
    """3,000 random id images (1 to 9 rows and columns, -1 for none, runs of one id) of up to 12 triangles over
    3 to 14 vertices (many share one): occlusion_boundary equals the pixel-by-pixel definition, with the
    shown pixels' box given and found."""
    from wirecheck.oracles.judge.metrics import occlusion_boundary

    rng = np.random.default_rng(109)
    marked = 0
    for _ in range(3000):
        n_tris, n_verts = int(rng.integers(1, 13)), int(rng.integers(3, 15))
        tris = np.stack([rng.choice(n_verts, 3, replace=False) for _ in range(n_tris)])
        h, w = (int(v) for v in rng.integers(1, 10, size=2))
        ids = np.repeat(rng.integers(-1, n_tris, size=(h, w)), rng.integers(1, 4), axis=1)[:, :w]
        want = _naive_occlusion_boundary(ids, tris)
        np.testing.assert_array_equal(occlusion_boundary(ids, tris), want)
        rows, cols = np.flatnonzero((ids >= 0).any(axis=1)), np.flatnonzero((ids >= 0).any(axis=0))
        if len(rows):
            box = np.s_[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
            np.testing.assert_array_equal(occlusion_boundary(ids, tris, box), want)
        marked += int(want.sum())
    assert marked > 10_000


def _within_naive(mask_from, mask_to, tol):
    """The definition, pixel by pixel: a True of mask_to in the (2 tol + 1)^2 window, clipped to the image."""
    h, w = mask_to.shape
    return np.array(
        [
            mask_to[max(r - tol, 0) : r + tol + 1, max(c - tol, 0) : c + tol + 1].any()
            for r, c in zip(*np.nonzero(mask_from))
        ],
        bool,
    )


@pytest.mark.parametrize("seed", range(12))
def test_one_pixel_match_on_drawn_pixels_equals_the_definition(seed):
    from wirecheck.oracles.judge.metrics import _within

    rng = np.random.default_rng(seed)
    h, w = rng.integers(1, 30, 2)
    a = rng.random((h, w)) < rng.uniform(0, 0.5)
    b = rng.random((h, w)) < rng.uniform(0, 0.2)
    b[0, :] |= rng.random(w) < 0.5  # lines along the border: the window is clipped there
    for tol in (0, 1, 2):
        np.testing.assert_array_equal(_within(a, b, tol), _within_naive(a, b, tol))


def _neighbourhoods_naive(p0, p1, w, h, pixels, radius=1.0):
    """The definition, pixel by pixel: the nearest segment within ``radius`` (ties: the lower index)."""
    rows = []
    for pix in pixels:
        c = np.array([pix % w, pix // w], float)
        best = None
        for e, (a, b) in enumerate(zip(p0, p1)):
            if not np.all(np.isfinite([a, b])):
                continue
            d = b - a
            u = 0.0 if d @ d == 0 else min(max((c - a) @ d / (d @ d), 0.0), 1.0)
            dist = np.linalg.norm(c - a - u * d)
            if dist <= radius and (best is None or dist < best[0]):
                best = (dist, e, pix % w if abs(d[0]) > abs(d[1]) else pix // w)
        if best is not None:
            rows.append((best[1], int(pix), int(best[2])))
    return rows


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("density", [0.02, 0.6])
def test_edge_neighbourhoods_of_drawn_pixels_equal_the_definition(seed, density):
    # density 0.02: few drawn pixels, found from the pixels (pixels x segments); 0.6: from
    # 1-px steps along the segments. Non-integer ends: no exact distance ties to decide.
    from wirecheck.oracles.judge.metrics import edge_neighbourhoods

    rng = np.random.default_rng(seed)
    w, h = 36, 24
    p0 = rng.uniform(-3, 39, (10, 2))
    p1 = p0 + rng.normal(0, 12, (10, 2))
    p1[2] = p0[2] + 0.3  # a very short segment
    p0[5] = np.nan  # an edge not drawn
    pixels = np.flatnonzero(rng.random(w * h) < density)
    got = edge_neighbourhoods(p0, p1, w, h, pixels=pixels)
    assert list(zip(*(a.tolist() for a in got))) == _neighbourhoods_naive(p0, p1, w, h, pixels)
    assert got[1].tolist() == sorted(got[1].tolist())  # one row per pixel, in pixel order


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("levels", ["radius only", "1/2 first", "1/8 and 1/2 first", "1/2 first, no table"])
def test_nearest_looked_for_near_first_equals_the_definition(monkeypatch, seed, levels):
    """segment_pixels looks within 1/2 px (a soup: 1/8, then 1/2) before the radius, for many pixels:
    forced here on a small image, where random pixels lie at every distance from the segments (some
    nearest within 1/8, some only between 1/2 and 1, some farther). The pixels left after a radius
    are paired with the segments whose boxes hold one (a summed-area table), or without the table
    with every segment."""
    from wirecheck.oracles.judge import segment_pixels
    from wirecheck.oracles.judge.metrics import edge_neighbourhoods

    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 10**9 if levels == "radius only" else 0)
    monkeypatch.setattr(segment_pixels, "TABLE_CELLS", 0 if levels.endswith("no table") else 1 << 23)
    monkeypatch.setattr(segment_pixels, "CROWDED", 0 if levels.startswith("1/8") else 10**9)
    rng = np.random.default_rng(40 + seed)
    w, h = 40, 30
    p0 = rng.uniform(-3, 43, (25, 2))
    p1 = p0 + rng.normal(0, 8, (25, 2))
    pixels = np.flatnonzero(rng.random(w * h) < 0.5)
    got = edge_neighbourhoods(p0, p1, w, h, pixels=pixels)
    assert list(zip(*(a.tolist() for a in got))) == _neighbourhoods_naive(p0, p1, w, h, pixels)


@pytest.mark.parametrize("levels", ["radius only", "1/2 first", "1/8 and 1/2 first"])
def test_nearest_beyond_half_a_pixel_and_tied(monkeypatch, levels):
    """Two horizontal segments 1.5 px apart, y = 4.25 (edge 0) and 5.75 (edge 1), x 0..20: row 4 is 1/4
    from edge 0, row 6 1/4 from edge 1, row 5 3/4 from both (a tie beyond every first radius: edge 0,
    the lower index), rows 3 and 7 1.25 from the nearer (no edge within 1)."""
    from wirecheck.oracles.judge import segment_pixels
    from wirecheck.oracles.judge.metrics import edge_neighbourhoods

    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 10**9 if levels == "radius only" else 0)
    monkeypatch.setattr(segment_pixels, "CROWDED", 0 if levels.startswith("1/8") else 10**9)
    w, h = 24, 12
    p0, p1 = np.array([[0.0, 4.25], [0.0, 5.75]]), np.array([[20.0, 4.25], [20.0, 5.75]])
    pixels = np.arange(3 * w, 8 * w)  # rows 3..7, every column
    edge, pixel, major = (a.tolist() for a in edge_neighbourhoods(p0, p1, w, h, pixels=pixels))
    # within 1 of a segment: x from 0 to 20 only (x = 21 is hypot(1, 1/4) = 1.03 from the nearer end)
    expected = (
        [(0, 4 * w + x) for x in range(21)] + [(0, 5 * w + x) for x in range(21)] + [(1, 6 * w + x) for x in range(21)]
    )
    assert list(zip(edge, pixel)) == expected
    assert major == [p % w for p in pixel]  # horizontal: the column


@pytest.mark.parametrize("seed", range(6))
def test_frames_neighbourhoods_give_each_frame_its_own_rows(seed):
    """Frames paired in one pass (stacked with a gap) get the definition's rows, frame by frame.

    The frames' segments reach past the image's top and bottom, where the
    stacked frames meet: a pair across two frames would show up as a row
    the definition does not have.
    """
    from wirecheck.oracles.judge.metrics import frames_neighbourhoods

    rng = np.random.default_rng(100 + seed)
    w, h = 30, 12
    frames = []
    for _ in range(int(rng.integers(2, 6))):
        n = int(rng.integers(0, 8))
        p0 = rng.uniform(-4, 34, (n, 2))
        p1 = np.column_stack([rng.uniform(-4, 34, n), rng.choice([-3.5, 15.5], n)])  # through top or bottom
        if n > 1:
            p1[1, 1] = p0[1, 1]  # horizontal
        frames.append((p0, p1, np.flatnonzero(rng.random(w * h) < rng.uniform(0.05, 0.7))))
    got = frames_neighbourhoods(frames, w, h)
    assert len(got) == len(frames)
    for (p0, p1, pixels), rows in zip(frames, got):
        assert list(zip(*(a.tolist() for a in rows))) == _neighbourhoods_naive(p0, p1, w, h, pixels)


@pytest.mark.parametrize("dense", [False, True], ids=["long-segments", "dense-mesh"])
def test_line_batch_scores_as_frame_by_frame(dense):
    """LineBatch's scores equal line_scores of each frame alone, whether it flushes on size or at the end.

    Long segments take the midpoint and one-sided path of frames_count_differences;
    many short ones (more than one per DENSE drawn pixels) the one-pass path.
    """
    from wirecheck.oracles.judge.metrics import FramePixels, LineBatch, line_scores

    rng = np.random.default_rng(5)
    w, h = 40, 30
    frames = []
    for k in range(7):
        if dense:
            p0 = rng.uniform(0, 30, (80, 2))
            p1 = p0 + rng.uniform(-2, 2, (80, 2))
        else:
            p0, p1 = rng.uniform(0, 40, (6, 2)), rng.uniform(0, 30, (6, 2))
        cand, orac = rng.random((h, w)) < 0.1, rng.random((h, w)) < 0.1
        frames.append((k, cand, orac, p0, p1))
    alone = [line_scores(c, o, p0, p1) for _, c, o, p0, p1 in frames]
    for limit in (1, 50, 1 << 20):  # every frame alone, a few together, all together
        batch, got = LineBatch(limit=limit), []
        for k, c, o, p0, p1 in frames:
            got += batch.add(k, FramePixels(c, o), p0, p1)
        got += batch.flush()
        assert [k for k, _ in got] == list(range(7))
        assert [s for _, s in got] == alone


def test_line_batch_counts_by_hand():
    """Edge counts where frames mostly agree (the midpoint path), with a duplicate edge and a short line.

    40 x 20 image. Edge 0: (2, 5) -> (30, 5), a row of 29 pixels; edge 1 the
    same segment again (its pixels are equally near both: they go to edge 0,
    the lower index, so edge 1 counts nothing and is not compared); edge 2:
    (10, 12) -> (10, 17), a column of 6 pixels. The candidate lacks edge 2's
    last pixel (10, 17): edge 2 counts 5 against the oracle's 6, diff -1.
    """
    from wirecheck.oracles.judge.metrics import FramePixels, LineBatch, line_scores

    p0 = np.array([[2.0, 5.0], [2.0, 5.0], [10.0, 12.0]])
    p1 = np.array([[30.0, 5.0], [30.0, 5.0], [10.0, 17.0]])
    oracle = np.zeros((20, 40), bool)
    oracle[5, 2:31] = True
    oracle[12:18, 10] = True
    cand = oracle.copy()
    cand[17, 10] = False
    batch = LineBatch()
    got = batch.add("same", FramePixels(oracle, oracle), p0, p1) + batch.add("short", FramePixels(cand, oracle), p0, p1)
    got += batch.flush()
    scores = dict(got)
    assert scores["same"]["edges_compared"] == 2 and scores["same"]["edge_count_max_diff"] == 0
    short = scores["short"]
    assert (short["edges_compared"], short["edge_count_worst_edge"], short["edge_count_worst_diff"]) == (2, 2, -1)
    assert short["edge_count_diff_sum"] == -1
    assert scores["short"] == line_scores(cand, oracle, p0, p1)  # the full count over every drawn pixel


def test_line_scores_with_nothing_drawn_near_an_edge_on_screen():
    from wirecheck.oracles.judge.metrics import line_scores

    blank = np.zeros((24, 36), bool)
    s = line_scores(blank, blank, np.array([[2.0, 3.0]]), np.array([[30.0, 20.0]]))
    assert (s["candidate_only"], s["oracle_only"], s["edges_compared"], s["edge_count_max_diff"]) == (0, 0, 0, 0)


@pytest.mark.parametrize("how", ["flat", "bits"])
def test_kept_image_gives_the_image_back(how):
    """worst.gif's kept frames: a wireframe kept as its drawn pixels' indices, a silhouette as bits."""
    from wirecheck.oracles.judge.wire_frames import KeptImage

    image = np.zeros((5, 7), bool)
    image[0, 0] = image[4, 6] = image[2, 3] = True  # the corners and the middle
    kept = KeptImage.of(image, np.flatnonzero(image) if how == "flat" else None)
    assert (kept.flat is not None) == (how == "flat")
    np.testing.assert_array_equal(kept.image(), image)


def _is_tie(c, a, b, other, end_px=2.0**-8):
    """oracles.judge.line_ties' rule for one pixel ``c`` of segment ``a -> b``, written out per axis (y-major first)."""
    d = b - a
    for major in (1, 0):
        minor = 1 - major
        if d[major] == 0 or abs(d[major]) < abs(d[minor]):
            continue
        t = (c[major] - a[major]) / d[major]
        if not 0 <= t <= 1:
            continue
        off = a[minor] + t * d[minor] - c[minor]
        if abs(abs(off) - 0.5) <= (1 + abs(d[minor] / d[major])) * end_px:
            p = c.astype(int)
            p[minor] += 1 if off > 0 else -1
            h, w = other.shape
            return bool(0 <= p[0] < w and 0 <= p[1] < h and other[p[1], p[0]])
    return False


def _is_end_tie(c, a, b, w, h, end_px=2.0**-8):
    """oracles.judge.line_ties' end rule for one pixel ``c`` of segment ``a -> b``, end by end: | |E - c|_1 - 1/2 |
    within 2 end_px, on the diamond's exit side (L1 distance growing along b - a), not an end on the border."""
    d, zone = b - a, 2 * end_px
    if not d.any():
        return False
    for e in (a, b):
        if min(abs(e[0] + 0.5), abs(e[0] - (w - 0.5)), abs(e[1] + 0.5), abs(e[1] - (h - 0.5))) <= 1e-6:
            continue
        off = e - c
        slope = sum(abs(d[k]) if abs(off[k]) <= zone else np.sign(off[k]) * d[k] for k in (0, 1))
        if abs(abs(off).sum() - 0.5) <= zone and slope >= 0:
            return True
    return False


def _ends_naive(cand, oracle, p0, p1, reach=1.5):
    """end_attribution's definition, pixel by pixel: the nearest segment (clipped to the image's edges)."""
    from wirecheck.oracles.segment_geometry import clip_to_box

    h, w = cand.shape
    ok, q0, q1 = clip_to_box(p0, p1, np.array([-0.5, -0.5]), np.array([w - 0.5, h - 0.5]))
    q0, q1 = q0[ok], q1[ok]
    out = {k: [0, 0] for k in ("start", "end", "middle", "stray", "tie")}
    other = (oracle, cand)
    for side, only in enumerate((cand & ~oracle, oracle & ~cand)):
        for y, x in zip(*np.nonzero(only)):
            c = np.array([x, y], float)
            best = None
            for a, b in zip(q0, q1):
                d = b - a
                u = 0.0 if d @ d == 0 else min(max((c - a) @ d / (d @ d), 0.0), 1.0)
                dist = np.hypot(*(c - a - u * d))
                if best is None or dist < best[0]:
                    best = (dist, a, b)
            if best is None or best[0] > reach:
                out["stray"][side] += 1
                continue
            if _is_tie(c, best[1], best[2], other[side]) or _is_end_tie(c, best[1], best[2], w, h):
                out["tie"][side] += 1
                continue
            s, e = np.hypot(*(c - best[1])) <= reach, np.hypot(*(c - best[2])) <= reach
            out["start" if s and not e else "end" if e and not s else "middle"][side] += 1
    return out


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("prefilter", [False, True], ids=["all-segments", "reaching-only"])
def test_end_attribution_equals_the_definition(monkeypatch, seed, prefilter):
    # reaching-only: segment_pixels.nearest_segments keeps only the segments whose boxes (whole cells of
    # 8 px) reach a one-sided pixel, forced here on 9 segments (by default from 4096 on)
    from wirecheck.oracles.judge import segment_pixels
    from wirecheck.oracles.judge.metrics import end_attribution

    monkeypatch.setattr(segment_pixels, "FEW_SEGMENTS", 0 if prefilter else 10**9)

    rng = np.random.default_rng(200 + seed)
    w, h = 30, 20
    p0 = rng.uniform(-5, 35, (9, 2))
    p1 = p0 + rng.normal(0, 8, (9, 2))
    p1[3] = p0[3]  # a point
    p0[4] = np.nan  # not drawn
    cand, oracle = rng.random((h, w)) < 0.15, rng.random((h, w)) < 0.15
    assert end_attribution(cand, oracle, p0, p1) == _ends_naive(cand, oracle, p0, p1)


@pytest.mark.parametrize("prefilter", [False, True], ids=["all-segments", "reaching-only"])
def test_end_attribution_equals_the_definition_at_ties(monkeypatch, prefilter):
    # segment ends on the half-pixel grid: many rows are crossed exactly at a pixel's edge (sub-pixel ties)
    from wirecheck.oracles.judge import segment_pixels
    from wirecheck.oracles.judge.metrics import end_attribution

    monkeypatch.setattr(segment_pixels, "FEW_SEGMENTS", 0 if prefilter else 10**9)

    ties = 0
    for seed in range(8):
        rng = np.random.default_rng(300 + seed)
        w, h = 30, 20
        p0 = np.round(rng.uniform(-5, 35, (9, 2)) * 2) / 2
        p1 = p0 + np.round(rng.normal(0, 8, (9, 2)) * 2) / 2
        cand, oracle = rng.random((h, w)) < 0.3, rng.random((h, w)) < 0.3
        got = end_attribution(cand, oracle, p0, p1)
        assert got == _ends_naive(cand, oracle, p0, p1)
        ties += sum(got["tie"])
    assert ties > 0  # the tie rule was exercised


def test_vertex_errors_frames_equal_frame_by_frame():
    """A case's frames scored together give each frame's own vertex_errors, to the bit (NaN rows: clipped)."""
    import json

    from wirecheck.oracles.judge.metrics import vertex_errors, vertex_errors_frames

    rng = np.random.default_rng(9)
    cand = [rng.normal(300, 200, (13, 2)) for _ in range(10)]
    orac = [c + rng.normal(0, 1e-3, c.shape) for c in cand]
    cand[2][4] = np.nan  # clipped by the candidate only: shown by the oracle only
    orac[5][0] = np.nan  # clipped by the oracle only: shown by the candidate only
    cand[7][3, 1] = np.inf  # a broken answer
    got = vertex_errors_frames(cand, orac)
    assert json.dumps(got) == json.dumps([vertex_errors(c, o) for c, o in zip(cand, orac)])
    assert got[2]["oracle_only"] == 1 and got[5]["candidate_only"] == 1 and got[7]["max_px"] == float("inf")


@pytest.mark.parametrize("seed", range(6))
def test_resolve_ties_by_a_merge_equals_the_pixels_looked_up_again(seed):
    """line_ends.resolve_ties moves the tie pixels by a merge (FramePixels.exchanged); the frame it gives
    equals FramePixels.from_indices of the changed candidate pixels (binary searches over every pixel),
    array for array; pixels that are not one-sided are refused (None)."""
    from wirecheck.oracles.judge.frame_pixels import FramePixels
    from wirecheck.oracles.judge.line_ends import resolve_ties

    rng = np.random.default_rng(500 + seed)
    h, w = 20, 30
    fp = FramePixels(rng.random((h, w)) < 0.3, rng.random((h, w)) < 0.3)
    c_only, o_only = fp.only()
    c_ties = np.sort(rng.choice(c_only, len(c_only) // 2, replace=False))
    o_ties = np.sort(rng.choice(o_only, len(o_only) // 3, replace=False))
    got = resolve_ties(fp, (c_ties, o_ties))
    want_cand = np.union1d(np.setdiff1d(fp.cand_idx, c_ties), o_ties)
    want = FramePixels.from_indices(fp.shape, want_cand, fp.oracle_idx)
    for name in ("cand_idx", "oracle_idx", "cand_in_oracle", "oracle_in_cand"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)
    assert got.only()[0].tolist() == np.setdiff1d(c_only, c_ties).tolist()
    both = fp.cand_idx[fp.cand_in_oracle][:1]  # drawn by both: no tie of one side
    assert fp.exchanged(both, o_ties[:0]) is None and fp.exchanged(c_ties[:0], both) is None
