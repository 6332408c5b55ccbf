"""FMI 2.0 co-simulation slave (pythonfmu): cushion-spring clutch torque.

The class lives in the sibling ``cushion_slave``; this module only imports
it. pythonfmu's binary re-executes *this* file's source for every
``fmi2Instantiate`` (``findClass``) into a fresh locals dictionary and then
releases the module's globals dictionary once more than it acquired it
(``Py_DECREF`` of the borrowed ``PyModule_GetDict`` result). Two things here
compensate, so that many instances neither leak classes nor free the
module dictionary under the interpreter (the teardown abort):

- re-executing an import binds the cached class, so no new class object
  (which the wrapper's leaked MRO list would keep alive) is made per instance;
- each re-execution takes one extra reference to this module's globals,
  balancing the wrapper's extra release.
"""
import sys as _sys

if locals() is not globals():        # re-executed by pythonfmu's findClass, not a normal import
    _sys.__dict__.setdefault("_cushion_clutch_globals_refs", []).append(globals())

from cushion_slave import CushionClutch  # noqa: E402,F401
