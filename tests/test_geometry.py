import numpy as np
import pytest

from cushion_clutch.fe.geometry import half_pair_assembly, pair_assembly, paddle_mesh, strip_mesh, wave_height
from cushion_clutch.fe.params import Geometry


def test_wave_is_one_minus_cos_between_its_angles():
    g = Geometry()
    phi = np.linspace(0, g.span_deg, 1001)
    w = wave_height(0.09, phi, g)
    assert w.max() == pytest.approx(g.wave_height_m, rel=1e-6)
    mid = 0.5 * (g.wave_start_deg + g.wave_end_deg)
    assert wave_height(0.09, np.array([mid]), g)[0] == pytest.approx(g.wave_height_m)
    assert np.all(w[phi <= g.wave_start_deg] == 0)


def test_paddle_sets_and_orientation():
    g = Geometry()
    m = paddle_mesh(g, 2e-3)
    phi = np.degrees(np.arctan2(m.nodes[:, 1], m.nodes[:, 0]))
    assert np.all(phi[m.node_sets["CLAMP"]] <= g.clamp_end_deg + 1e-9)
    assert np.allclose(phi[m.node_sets["FAR_END"]], g.span_deg)
    # crest node at the top of the wave
    crest = m.nodes[m.node_sets["CREST"][0]]
    assert crest[2] == pytest.approx(0.5 * g.thickness_m + g.carrier_clearance_m + g.wave_height_m)
    # counter-clockwise elements: +z normals on a flat patch
    a, b, c = (m.nodes[m.elements[0, i]] for i in range(3))
    assert np.cross(b - a, c - a)[2] > 0
    # clamped elements are not contact elements
    assert len(m.element_sets["CONTACT"]) < m.n_elements


def test_pair_is_mirror_of_half():
    g = Geometry()
    half = half_pair_assembly(g, 2e-3, 0.15e-3)
    pair = pair_assembly(g, 2e-3, 0.15e-3)
    n = half.mesh.n_nodes
    assert pair.mesh.n_nodes == 2 * n
    assert np.allclose(pair.mesh.nodes[n:, 2], -half.mesh.nodes[:, 2])
    up, lo = pair.plates
    assert up.z_face_m == pytest.approx(-lo.z_face_m)


def test_strip_mesh_sets():
    m = strip_mesh(0.04, 0.004, 0.4e-3, 1e-3)
    assert m.n_elements == 40 * 4
    assert np.allclose(m.nodes[m.node_sets["END1"], 0], 0.04)


def test_tilted_wave_has_its_edge_heights_and_the_mean_at_mid_radius():
    g = Geometry(wave_tilt_m=0.4e-3)
    crest = 0.5 * (g.wave_start_deg + g.wave_end_deg)
    r_mean = 0.5 * (g.inner_radius_m + g.outer_radius_m)
    assert wave_height(g.inner_radius_m, crest, g) == pytest.approx(0.5e-3)
    assert wave_height(g.outer_radius_m, crest, g) == pytest.approx(0.9e-3)
    assert wave_height(r_mean, crest, g) == pytest.approx(0.7e-3)
    assert g.max_wave_height_m == pytest.approx(0.9e-3)


def test_several_waves_repeat_the_profile():
    g = Geometry(waves=3)
    phi = np.linspace(g.wave_start_deg, g.wave_end_deg, 3001)
    w = wave_height(0.09, phi, g)
    peaks = np.flatnonzero((w[1:-1] > w[:-2]) & (w[1:-1] >= w[2:]))
    assert len(peaks) == 3
    assert w.max() == pytest.approx(g.wave_height_m, rel=1e-4)
    assert wave_height(0.09, g.wave_start_deg + 5.0, g) == pytest.approx(0.0, abs=1e-12)


def test_flat_top_crest_is_flat_over_its_fraction_and_matches_cosine_at_zero():
    g = Geometry(wave_profile="flat_top", crest_flat_fraction=0.4)
    span = g.wave_end_deg - g.wave_start_deg
    phi = g.wave_start_deg + span * np.linspace(0.31, 0.69, 50)
    assert np.allclose(wave_height(0.09, phi, g), g.wave_height_m)
    cos0 = Geometry(wave_profile="flat_top", crest_flat_fraction=0.0)
    phi = np.linspace(0, g.span_deg, 301)
    assert np.allclose(wave_height(0.09, phi, cos0), wave_height(0.09, phi, Geometry()))


def test_table_profile_interpolates_its_points():
    g = Geometry(wave_profile="table", profile_s=(0.0, 0.25, 0.5, 1.0), profile_z=(0.0, 1.0, 0.5, 0.0))
    span = g.wave_end_deg - g.wave_start_deg
    assert wave_height(0.09, g.wave_start_deg + 0.25 * span, g) == pytest.approx(g.wave_height_m)
    assert wave_height(0.09, g.wave_start_deg + 0.75 * span, g) == pytest.approx(0.25 * g.wave_height_m)
    m = paddle_mesh(g, 2e-3)
    assert m.nodes[:, 2].max() == pytest.approx(0.5 * g.thickness_m + g.carrier_clearance_m + g.wave_height_m)


def test_far_zone_on_the_carrier_is_contact_not_guide():
    slot = paddle_mesh(Geometry(), 2e-3)
    rest = paddle_mesh(Geometry(far_zone_support="carrier"), 2e-3)
    assert len(slot.node_sets["GUIDE"]) > 0 and len(rest.node_sets["GUIDE"]) == 0
    assert len(rest.element_sets["CONTACT"]) > len(slot.element_sets["CONTACT"])


def test_eight_node_mesh_has_mid_side_nodes_and_no_orphans():
    g = Geometry(wave_tilt_m=0.2e-3)
    m = paddle_mesh(g, 2e-3, element_type="S8R")
    lin = paddle_mesh(g, 2e-3)
    assert m.elements.shape == (lin.n_elements, 8)
    assert len(np.unique(m.elements)) == m.n_nodes
    e = m.elements[len(m.elements) // 2]
    for mid, (a, b) in zip(e[4:], [(e[0], e[1]), (e[1], e[2]), (e[2], e[3]), (e[3], e[0])]):
        assert np.allclose(m.nodes[mid, :2], 0.5 * (m.nodes[a, :2] + m.nodes[b, :2]), atol=2e-5)
    assert len(m.node_sets["CLAMP"]) > len(lin.node_sets["CLAMP"])


@pytest.mark.parametrize("kw, match", [
    ({"waves": 0}, r"geometry\.waves = 0: must be an integer in \[1, 8\]"),
    ({"wave_tilt_m": 2e-3}, r"geometry\.wave_tilt_m = 0\.002: out of range, allowed \[-0\.0014, 0\.0014\]"),
    ({"wave_profile": "sine"}, r"geometry\.wave_profile = 'sine': allowed"),
    ({"crest_flat_fraction": 0.9}, r"geometry\.crest_flat_fraction = 0\.9: out of range, allowed \[0, 0\.8\]"),
    ({"wave_profile": "table", "profile_s": (0.0, 0.6, 0.5, 1.0), "profile_z": (0, 1, 1, 0)},
     r"geometry\.profile_s: must rise strictly"),
    ({"wave_profile": "table", "profile_s": (0.0, 0.5, 1.0), "profile_z": (0.0, 0.7, 0.0)},
     r"geometry\.profile_z: must start and end at 0 and peak at 1"),
    ({"far_zone_support": "glued"}, r"geometry\.far_zone_support = 'glued': allowed 'slot' or 'carrier'"),
])
def test_new_geometry_keys_are_checked(kw, match):
    from cushion_clutch.errors import ParameterError
    with pytest.raises(ParameterError, match=match):
        Geometry(**kw)
