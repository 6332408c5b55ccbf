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
