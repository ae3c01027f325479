# SPDX-License-Identifier: BSD-3-Clause
"""The module's type hints (PEP 561): py.typed is in the package, and every public function of
bricking, volume, _check, errors and stats annotates its parameters and its return, with
annotations that resolve (typing.get_type_hints)."""
import inspect
import os
import typing
import unittest

import support  # first: it skips (status 77) when numpy is absent
import isoprop
from isoprop import _check, bricking, errors, stats, volume


def public_functions():
    """(name, function) of each module's public functions and of its public classes' public
    methods (and __init__), defined in that module."""
    for module in (bricking, volume, _check, errors, stats):
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if inspect.isfunction(obj):
                yield "%s.%s" % (module.__name__, name), obj
            elif inspect.isclass(obj):
                for attr, fn in vars(obj).items():
                    if inspect.isfunction(fn) and (not attr.startswith("_") or
                                                   attr in ("__init__", "__enter__",
                                                            "__exit__")):
                        yield "%s.%s.%s" % (module.__name__, name, attr), fn


class Types(unittest.TestCase):
    def test_py_typed(self):
        self.assertTrue(os.path.isfile(os.path.join(os.path.dirname(isoprop.__file__),
                                                    "py.typed")))

    def test_public_functions_annotated(self):
        seen = 0
        for name, fn in public_functions():
            with self.subTest(function=name):
                signature = inspect.signature(fn)
                for p in signature.parameters.values():
                    if p.name != "self":
                        self.assertIsNot(p.annotation, p.empty, "%s: %s" % (name, p.name))
                self.assertIsNot(signature.return_annotation, signature.empty, name)
                typing.get_type_hints(fn)  # every annotation resolves
                seen += 1
        self.assertGreater(seen, 30)


if __name__ == "__main__":
    support.main()
