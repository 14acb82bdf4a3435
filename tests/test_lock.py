"""requirements.lock pins every package the README's commands install.

Walks the installed mesoforge's requirements (the test extras included)
through the installed distributions' own metadata, so a dependency added to
pyproject.toml, or a new transitive one, without refreshing the lock fails
here, and so does an environment that drifted from the lock.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

LOCK = Path(__file__).resolve().parent.parent / "requirements.lock"


def _locked() -> dict[str, str]:
    pins = {}
    for line in LOCK.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, _, version = line.partition("==")
            assert version, f"requirements.lock: {line!r} is not pinned with =="
            pins[canonicalize_name(name)] = version
    return pins


def _needed(root: str, extras: tuple[str, ...]) -> set[str]:
    """Canonical names of every distribution `root` needs, transitively."""
    seen: set[str] = set()
    todo = [(root, extras)]
    while todo:
        name, wanted = todo.pop()
        for text in metadata.requires(name) or ():
            req = Requirement(text)
            env = default_environment()
            if req.marker is not None and not any(
                    req.marker.evaluate({**env, "extra": e}) for e in (wanted or ("",))):
                continue
            key = canonicalize_name(req.name)
            if key not in seen:
                seen.add(key)
                todo.append((req.name, tuple(req.extras)))
    return seen


def test_every_installed_requirement_is_pinned_at_its_installed_version():
    pins = _locked()
    needed = _needed("mesoforge", ("test",))
    assert {"numpy", "scipy", "pyside6-essentials", "hypothesis"} <= needed
    missing = sorted(needed - set(pins))
    assert not missing, f"not in requirements.lock (run bash scripts/lock.sh): {missing}"
    drifted = {n: (pins[n], metadata.version(n)) for n in needed if metadata.version(n) != pins[n]}
    assert not drifted, f"installed versions differ from requirements.lock: {drifted}"


def test_the_build_backend_is_pinned_within_its_range():
    import tomllib

    pins = _locked()
    build = tomllib.loads((LOCK.parent / "pyproject.toml").read_text())["build-system"]["requires"]
    for text in build:
        req = Requirement(text)
        key = canonicalize_name(req.name)
        assert key in pins, f"build requirement {req.name} is not in requirements.lock"
        assert req.specifier.contains(pins[key]), f"{req.name}=={pins[key]} is outside {req.specifier}"
