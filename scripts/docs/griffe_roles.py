"""A Griffe extension for the API reference: the package's docstrings as mkdocstrings reads them.

- The docstrings use Sphinx's cross-reference roles (``:func:`collide```,
  ``:class:`~cloudprox.Mesh```, ``:mod:`.poses```). mkdocstrings renders Markdown,
  so each role becomes inline code, and a cross-reference link where the target
  is a full ``cloudprox`` path of the package.
- The compiled classes are made by ``__new__`` (PyO3), which their stub
  (``_native.pyi``) declares, while mkdocstrings shows a class's constructor from
  ``__init__``: such a class gets an ``__init__`` with ``__new__``'s parameters,
  so its signature is shown and its docstring's parameters are checked against it.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

#: ``:role:`target``` or ``:role:`~target```.
ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const):`(~?)([^`]+)`")


def _resolve(target: str, obj: griffe.Object, known: set[str]) -> str | None:
    """Return the full path ``target`` names in ``obj``'s docstring, if the package has it."""
    module = obj.module.path
    if target.startswith("."):  # relative to the module's package: ``:mod:`.poses```
        package = module if obj.module.is_init_module else module.rsplit(".", 1)[0]
        candidates = [package + target]
    else:
        candidates = [target, f"cloudprox.{target}", f"{module}.{target}"]
        if obj.parent is not None:
            candidates.append(f"{obj.parent.path}.{target}")
        if obj.parent is not None and obj.parent.parent is not None:
            candidates.append(f"{obj.parent.parent.path}.{target}")
    for path in candidates:
        # Compiled names are documented where the package exports them.
        public = path.replace("cloudprox._native.", "cloudprox.", 1)
        for p in (public, path):
            if p in known:
                return p
    return None


def _replace(match: re.Match[str], obj: griffe.Object, known: set[str]) -> str:
    tilde, target = match.group(1), match.group(2).strip()
    shown = target.rsplit(".", 1)[-1] if tilde else target.lstrip(".")
    path = _resolve(target, obj, known)
    if path is not None:
        return f"[`{shown}`][{path}]"
    return f"`{shown}`"


def _walk(obj: griffe.Object, seen: set[str], out: list[griffe.Object]) -> None:
    if obj.path in seen:
        return
    seen.add(obj.path)
    out.append(obj)
    for member in obj.members.values():
        if not member.is_alias:
            _walk(member, seen, out)  # type: ignore[arg-type]


def _init_from_new(cls: griffe.Class) -> None:
    """Give ``cls`` an ``__init__`` with the parameters of its own ``__new__``."""
    new = cls.members.get("__new__")
    if "__init__" in cls.members or not isinstance(new, griffe.Function):
        return
    params = list(new.parameters)[1:]  # without ``cls``
    self_param = griffe.Parameter("self", kind=griffe.ParameterKind.positional_or_keyword)
    init = griffe.Function(
        "__init__",
        lineno=new.lineno,
        endlineno=new.endlineno,
        parameters=griffe.Parameters(self_param, *params),
        returns=None,
        docstring=new.docstring,
    )
    cls.set_member("__init__", init)


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles in every docstring; constructors from ``__new__``."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        """Rewrite the docstrings once the whole package is loaded."""
        objects: list[griffe.Object] = []
        _walk(pkg, set(), objects)
        for o in objects:
            if isinstance(o, griffe.Class):
                _init_from_new(o)
        # Paths the reference renders: public names with a docstring, outside
        # the compiled module (documented where the package exports it).
        known = {
            o.path
            for o in objects
            if not any(part.startswith("_") for part in o.path.split("."))
            and (o.docstring is not None or o.is_module)
        }
        # Names a module re-exports in its ``__all__`` (``cloudprox.collide``) too.
        for o in objects:
            exports = o.exports if isinstance(o, griffe.Module) else None
            for name, member in o.members.items():
                if member.is_alias and exports is not None and name in exports:
                    known.add(f"{o.path}.{name}")
        for o in objects:
            if o.docstring is not None and ":" in o.docstring.value:
                o.docstring.value = ROLE.sub(
                    lambda m, o=o: _replace(m, o, known), o.docstring.value
                )
