"""The FE case engine (fe/cases.py): cache layout and atomic write, the ccx version in the key,
input files shipped to Dask workers (a scanned surface), clients made here closed."""
import shutil

import numpy as np
import pytest

from cushion_clutch.fe import cases
from cushion_clutch.fe.cases import Case, case_folder, case_key, run_cases, solve_remote
from cushion_clutch.fe.ccx import ccx_version
from cushion_clutch.fe.params import DEFAULT_SPRING, load_params
from cushion_clutch.fe.scan.importer import import_scan

from scan_synthetic import synthetic_scan, write_csv


def test_key_holds_the_solving_ccx_version_and_the_folder_layout(coarse, tmp_path):
    case = Case(coarse, 20.0)
    assert case_key(coarse, 20.0, 1, "2.20") != case_key(coarse, 20.0, 1, "2.21")
    folder = case_folder(tmp_path, case, "2.20")
    assert folder == tmp_path / coarse.name / f"theta_20_{case_key(coarse, 20.0, 1, '2.20')}"


def test_store_is_atomic_and_read_back(coarse, tmp_path):
    folder = tmp_path / "case"
    cases.store(folder, {"x": 1})
    assert (folder / "result.json").read_text() == '{"x": 1}'
    assert not (folder / "result.json.tmp").exists()


def test_a_scanned_surface_travels_with_the_task(tmp_path):
    """solve_remote needs only the surface's bytes: the file is gone from its path when the worker runs."""
    p = load_params()
    write_csv(tmp_path / "paddle.csv", synthetic_scan(p.geometry))
    scan = import_scan(tmp_path / "paddle.csv", DEFAULT_SPRING, tmp_path / "spring" / "scanned.toml")
    params = load_params(scan.toml)
    assert cases.input_files(params) == [params.geometry.surface_file]
    assert cases.input_files(p) == []


@pytest.mark.ccx
def test_remote_solve_uses_the_shipped_surface_not_the_path(coarse, tmp_path):
    d = tmp_path / "scan"
    d.mkdir()
    write_csv(d / "paddle.csv", synthetic_scan(coarse.geometry))
    scan = import_scan(d / "paddle.csv", DEFAULT_SPRING, d / "spring" / "scanned.toml")
    # 4 mm: the remote solve must equal the local one bit for bit on any mesh
    params = load_params(scan.toml).replace(mesh={"element_size_m": 4e-3})
    surface = params.geometry.surface_file
    blob = open(surface, "rb").read()
    local = cases.solve_case(params, 20.0, tmp_path / "local")
    moved = tmp_path / "elsewhere.npz"
    shutil.move(surface, moved)                       # a worker without the submitting machine's disk
    data, version = solve_remote(params, 20.0, 1, {surface: blob})
    assert version == ccx_version()
    assert np.array_equal(np.array(data["force_N"]), local.result.force_N)


@pytest.mark.ccx
def test_dask_run_closes_the_client_it_made_and_caches_with_the_workers_version(coarse, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    import contextlib
    made = []
    open_cluster = cases.open_cluster

    @contextlib.contextmanager
    def spy(scheduler, workers):
        with open_cluster(scheduler, workers) as (client, info):
            made.append((client, client.cluster))
            yield client, info

    monkeypatch.setattr(cases, "open_cluster", spy)
    # 4 mm: the cluster's life cycle and the cache are under test, not the mesh
    p = coarse.replace(mesh={"element_size_m": 4e-3}, sweep={"temperatures_degC": (20.0,)})
    outcomes, failures = run_cases([Case(p, 20.0, 1, "t")], cache_dir=tmp_path, jobs=1, local_cluster=True)
    assert failures == {} and outcomes[0] is not None and not outcomes[0].from_cache
    client, cluster = made[0]
    assert client.status == "closed" and cluster.status.name == "closed"
    assert (case_folder(tmp_path, Case(p, 20.0), ccx_version()) / "result.json").exists()
    again, _ = run_cases([Case(p, 20.0, 1, "t")], cache_dir=tmp_path, jobs=1, local_cluster=True)
    assert again[0].from_cache and len(made) == 1        # all cached: no cluster started
    assert isinstance(distributed.Client, type)
