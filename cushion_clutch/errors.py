"""Exception classes of cushion_clutch.

Every class subclasses a builtin so that callers may catch either the
specific class or the builtin it refines.
"""
from __future__ import annotations

from typing import Sequence


class ParameterError(ValueError):
    """One or more parameters are invalid.

    Parameters
    ----------
    problems : sequence of str
        Every problem found, each naming the key and the allowed range.
    source : str, optional
        Where the parameters came from (a file name), for the message.
    """

    def __init__(self, problems: Sequence[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        where = f" in {source}" if source else ""
        lines = "\n  - ".join(self.problems)
        super().__init__(f"{len(self.problems)} invalid parameter(s){where}:\n  - {lines}")


class CalculixNotFoundError(FileNotFoundError):
    """The CalculiX executable ``ccx`` is not on the PATH."""

    def __init__(self, executable: str = "ccx"):
        super().__init__(
            f"CalculiX executable '{executable}' not found on PATH. Install it with "
            "'apt-get install -y calculix-ccx' (Debian/Ubuntu) or set CCX to its path."
        )


class CalculixError(RuntimeError):
    """CalculiX ran but did not finish cleanly.

    Attributes
    ----------
    returncode : int
        The process exit code.
    log_tail : str
        The last lines of the solver output.
    """

    def __init__(self, message: str, returncode: int, log_tail: str):
        self.returncode = returncode
        self.log_tail = log_tail
        super().__init__(f"{message} (ccx exit code {returncode})\n--- ccx log tail ---\n{log_tail}")


class ConvergenceError(CalculixError):
    """CalculiX did not converge.

    Attributes
    ----------
    theta_degC : float or None
        Temperature of the failing case, degC.
    step : int or None
        Step (1 thermal, 2 compression) that failed.
    increment : int or None
        Last increment attempted.
    """

    def __init__(self, message: str, returncode: int, log_tail: str, *,
                 theta_degC: float | None = None, step: int | None = None,
                 increment: int | None = None):
        self.theta_degC = theta_degC
        self.step = step
        self.increment = increment
        super().__init__(message, returncode, log_tail)


class CcxVersionError(RuntimeError):
    """Dask workers report different ccx versions, or a case was solved by another version than its key's."""


class ResultError(RuntimeError):
    """A finished FE case gives results that cannot be made into a table."""


class SweepError(RuntimeError):
    """A sweep had failed cases; finished cases are kept in the cache.

    Attributes
    ----------
    failures : dict
        Temperature (degC) to the exception raised for it.
    """

    def __init__(self, failures: dict):
        self.failures = failures
        lines = "\n".join(f"  theta = {t:g} degC: {e}" for t, e in sorted(failures.items()))
        super().__init__(
            f"{len(failures)} case(s) failed; finished cases are cached and no table was "
            f"written:\n{lines}")


class TableError(ValueError):
    """A lookup table file is missing, malformed or inconsistent."""


class FmuError(ValueError):
    """A file given as an FMU is not one, or lacks the CushionClutch interface."""


class RunInterrupted(KeyboardInterrupt):
    """A run was stopped by SIGINT (Ctrl-C) or SIGTERM; queued work was cancelled.

    Attributes
    ----------
    signum : int
        The signal number.
    exit_code : int
        ``128 + signum`` (130 for SIGINT, 143 for SIGTERM), the shell convention.
    """

    def __init__(self, signum: int):
        import signal
        self.signum = int(signum)
        self.exit_code = 128 + self.signum
        super().__init__(f"interrupted by {signal.Signals(self.signum).name}")


class ScanError(ParameterError):
    """A scanned paddle surface cannot be imported (too few points, wrong unit,
    outside the paddle sector, non-finite coordinates, unreadable file).

    Like :class:`ParameterError`, it lists every problem found.
    """

    def __init__(self, problems: Sequence[str], source: str | None = None, coverage=None):
        super().__init__(problems, source)
        #: the scan's point coverage (:class:`cushion_clutch.fe.scan.fit.Coverage`) when gaps refused it
        self.coverage = coverage
        where = f" {source}" if source else ""
        lines = "\n  - ".join(self.problems)
        self.args = (f"cannot import the scan{where}:\n  - {lines}",)

    def __str__(self) -> str:
        return self.args[0]


class StudyError(SweepError):
    """Cases of a tolerance study failed; finished cases are kept in the cache.

    Attributes
    ----------
    failures : dict
        ``(sample, theta_degC)`` to the exception raised for it.
    """

    def __init__(self, failures: dict):
        self.failures = failures
        lines = "\n".join(f"  sample {s}, theta = {t:g} degC: {e}" for (s, t), e in sorted(failures.items()))
        RuntimeError.__init__(
            self, f"{len(failures)} case(s) of the tolerance study failed; finished cases are cached "
                  f"(a rerun resumes) and no band was written:\n{lines}")


class ClusterError(RuntimeError):
    """A Dask cluster cannot run the FE cases: no worker, a worker that lacks the
    package or ccx, workers with different ccx versions, or workers lost mid-study.
    The message names every worker concerned; finished cases stay cached."""


class FmuCallError(RuntimeError):
    """An FMI function returned a status other than fmi2OK (or fmi2Warning).

    Attributes
    ----------
    function : str
        The FMI function, e.g. ``fmi2DoStep``.
    status : int
        The FMI status code (2 discard, 3 error, 4 fatal, 5 pending).
    """

    STATUS = {0: "fmi2OK", 1: "fmi2Warning", 2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal", 5: "fmi2Pending"}

    def __init__(self, function: str, status: int, detail: str = ""):
        self.function = function
        self.status = status
        name = self.STATUS.get(status, f"status {status}")
        super().__init__(f"{function} returned {name}" + (f" ({detail})" if detail else ""))
