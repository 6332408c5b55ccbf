"""The pythonfmu FMU keeps the native FMU's contract: the same seeded random FMI call sequences through
both FMI 2.0 Co-Simulation FMUs give the same status at every call and the same values (issue 31).

The generator and the drivers are :mod:`cushion_clutch.benchmarks.differential` (which runs the same at a
larger size); here 40 sequences, each FMU built once per session.
"""
import math

import pytest

from cushion_clutch.benchmarks import differential as D
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu
from native_builds import native_fmus

pytestmark = pytest.mark.fmu

SEQUENCES = 40


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    python = build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("differential") / "python2.fmu", backend="python")
    native, native3 = D.Fmi2CS(native_fmus()[2], "native2"), D.Fmi3CS(native_fmus()[3], "native3")
    py = D.Fmi2CS(python, "python2")
    yield native, py, native3
    for f in (native, py, native3):
        f.close()


def test_sequences_cover_what_the_contract_is_about():
    """The generator makes what the comparison needs: NaN, inf and out-of-range inputs, bad step sizes,
    saved/restored states, resets, and reads right after a set."""
    ops = [op for seed in range(SEQUENCES) for op in D.sequence(seed, 60, ["x_to", "torque"])]
    values = [v for op in ops if op[0] == "set" for v in op[1].values()]
    steps = [op[1] for op in ops if op[0] == "step"]
    assert sum(math.isnan(v) for v in values) >= 10 and sum(math.isinf(v) for v in values) >= 5
    assert sum(abs(v) > 1.0 for v in values if math.isfinite(v)) >= 10
    assert sum(math.isnan(h) for h in steps) >= 5 and sum(h < 0 for h in steps) >= 5
    kinds = [op[0] for op in ops]
    assert min(kinds.count(k) for k in ("save", "restore", "reset")) >= 10
    assert sum(a[0] == "set" and b[0] == "get" for a, b in zip(ops, ops[1:])) >= 100


def test_pythonfmu_fmu_answers_every_call_as_the_native_one(fmus):
    """40 seeded sequences: the same status at every call (fmi2Error and fmi2Warning too: the guard library
    returns the slave's) and the same values to 1e-9, all the way to each sequence's end."""
    native, python, _ = fmus
    outcomes = D.run(native, python, range(SEQUENCES), calls=60)
    diffs = [str(o.difference) for o in outcomes if o.difference is not None]
    assert diffs == [], f"{len(diffs)} of {SEQUENCES} sequences differ:\n" + "\n".join(diffs[:3])
    assert sum(o.calls for o in outcomes) == sum(len(D.sequence(s, 60, ["x"])) for s in range(SEQUENCES))
    assert sum(o.discards for o in outcomes) >= 40                   # refused steps and reads were compared
    assert sum(o.errors for o in outcomes) >= 3                      # e.g. a saved state with x_to = NaN
    assert sum(o.warnings for o in outcomes) >= 3                    # a step not where the last one ended
    assert sum(o.gets_after_set for o in outcomes) >= 100


def test_native_fmi3_answers_every_call_as_fmi2(fmus):
    """The native FMI 3.0 CS front end against the FMI 2.0 one on the same sequences."""
    native, _, native3 = fmus
    outcomes = D.run(native, native3, range(SEQUENCES), calls=60)
    diffs = [str(o.difference) for o in outcomes if o.difference is not None]
    assert diffs == [], "\n".join(diffs[:3])


def test_model_exchange_answers_every_call_as_co_simulation(fmus):
    """The native FMI 2.0 FMU's Model Exchange interface against its Co-Simulation one on the same sequences
    without their steps: the same status at every call (a read of an output after a refused input is Discard in
    both, never a stale value with OK) and the same values."""
    native = fmus[0]
    me = D.Fmi2ME(native.path, "native2me")
    try:
        outcomes = D.run(native, me, range(SEQUENCES), calls=60, steps=False)
    finally:
        me.close()
    diffs = [str(o.difference) for o in outcomes if o.difference is not None]
    assert diffs == [], f"{len(diffs)} of {SEQUENCES} sequences differ:\n" + "\n".join(diffs[:3])
    assert sum(o.discards for o in outcomes) >= 20                   # stale reads refused in both
    assert sum(o.gets_after_set for o in outcomes) >= 100


@pytest.mark.parametrize("which", [0, 1, 2])
def test_a_read_after_a_refused_input_is_never_a_stale_value_with_ok(fmus, which):
    """After a step, x_to = 1 m is set (accepted: fmi2OK, it is only an input) and torque read: Discard, in the
    native FMI 2.0 and 3.0 and the pythonfmu FMU alike; the state theta_cs reads OK; the refused step leaves
    fmi2Terminated false (the pythonfmu wrapper's own answer is true: the guard answers); a valid input recovers."""
    fmu = fmus[which]
    fmu.instantiate()
    try:
        assert fmu.init(0.0, {})[-1] == 0
        assert fmu.set({"x_to": 0.008}) == 0 and fmu.step(0.0, 0.1) == 0
        status, (torque,) = fmu.get(["torque"])
        assert status == 0 and torque > 100.0
        assert fmu.set({"x_to": 1.0}) == 0
        assert fmu.get(["torque"])[0] == 2, fmu.label
        assert fmu.get(["theta_cs"])[0] == 0, fmu.label
        assert any("x_to = 1" in m and "[-0.002, 0.025] m" in m for m in fmu.log.lines), fmu.log.lines
        assert fmu.step(0.1, 0.1) == 2
        if fmu.fmi == 2:                                           # a recoverable Discard: not Terminated
            assert fmu.slave.getBooleanStatus(3) is False, fmu.label
            assert fmu.slave.getRealStatus(2) == pytest.approx(0.1), fmu.label
        assert fmu.set({"x_to": 0.008}) == 0 and fmu.get(["torque"]) == (0, [torque])
        assert fmu.step(0.1, 0.1) == 0, fmu.label                  # and the next step proceeds
    finally:
        fmu.free()


def test_an_output_read_right_after_set_follows_the_input(fmus):
    """Issue 31's example: at x_to = 0 and 20 degC, set x_to = 8 mm and read the torque with no step in
    between, then 4 mm: both FMUs answer the new input's torque (the Python model's), not the previous one."""
    from cushion_clutch.model import ClutchParameters, load_table, outputs

    table, p = load_table(), ClutchParameters()
    for fmu in fmus[:2]:
        fmu.instantiate()
        try:
            assert fmu.init(0.0, {}) == [0, 0, 0]
            for x in (0.008, 0.004, 0.008):
                assert fmu.set({"x_to": x}) == 0
                status, (torque,) = fmu.get(["torque"])
                expected = outputs(x, p.theta_cs_start, table, p, theta_cm=p.theta_a).torque
                assert status == 0 and torque == pytest.approx(expected, rel=1e-9), (fmu.label, x)
            assert expected > 100.0
        finally:
            fmu.free()


def test_a_refused_value_is_forgotten_once_a_valid_one_comes(fmus):
    """Issue 31's example, on the cover of issue 28: worn facings (2.5 mm, past this cover's wear limit) and a
    hot start are refused at initialisation with fmi2Error in both FMUs; after fmi2Reset a valid start works,
    a refused input (x_to = 0.1 m) is discarded, and the next valid input recovers (the pythonfmu FMU used to
    keep a refusal forever)."""
    answers = []
    for fmu in fmus[:2]:
        fmu.instantiate()
        try:
            assert fmu.init(0.0, {"facing_wear": 2.5e-3, "theta_cs_start": 573.15})[-1] == 3, fmu.label
            assert fmu.reset() == 0
            assert fmu.init(0.0, {"facing_wear": 2.0e-3, "theta_cs_start": 573.15}) == [0, 0, 0, 0], fmu.label
            assert fmu.set({"x_to": 0.1}) == 0
            assert fmu.step(0.0, 0.1) == 2, fmu.label              # refused input: discarded
            assert fmu.set({"theta_cm": 700.0, "x_to": 0.012}) == 0
            status, (torque,) = fmu.get(["torque"])
            assert status == 0 and torque > 0.0, fmu.label
            assert fmu.step(0.0, 0.1) in (0, 1), fmu.label         # steps again (a Warning: beyond the tables)
            answers.append(torque)
        finally:
            fmu.free()
    assert answers[0] == pytest.approx(answers[1], rel=1e-9)


def test_error_and_warning_statuses_are_the_native_ones(fmus):
    """The pythonfmu FMU returns fmi2Error and fmi2Warning where the native one does (through its guard
    library), changes nothing on a refused call and is not left faulty by it."""
    for fmu in fmus[:2]:
        fmu.instantiate()
        try:
            assert fmu.init(0.0, {}) == [0, 0, 0], fmu.label
            assert fmu.set({"torque": 1.0}) == 3, fmu.label           # an output
            assert fmu.set({"x_to": 0.008, "mu": 0.5}) == 3, fmu.label  # a fixed parameter: refused as a whole
            assert fmu.get(["x_to", "mu"]) == (0, [0.0, 0.28]), fmu.label
            assert fmu.step(0.0, 0.1) == 0, fmu.label                  # not faulty afterwards
            assert fmu.step(0.05, 0.1) == 1, fmu.label                 # not where the last step ended: warned
            assert fmu.step(0.15, 0.1) == 0, fmu.label
        finally:
            fmu.free()


def test_messages_print_the_offending_value_exactly_and_the_same_range(fmus):
    """x_to = 0.025000001 m (just past the range): every front end's message prints a number that is exactly that
    value (native %.17g, pythonfmu repr; "%g" printed the limit itself) and the range [-0.002, 0.025] m."""
    import re
    value = 0.025000001
    for fmu in fmus:
        fmu.instantiate()
        try:
            assert fmu.init(0.0, {})[-1] == 0
            fmu.set({"x_to": value})
            fmu.log.lines = []                                     # this step's messages only
            assert fmu.step(0.0, 0.1) == 2, fmu.label
            line = next(m for m in fmu.log.lines if "x_to = " in m)
            printed = float(re.search(r"x_to = ([-+0-9.e]+) m", line).group(1))
            assert printed == value and "[-0.002, 0.025] m" in line, (fmu.label, line)
        finally:
            fmu.free()
