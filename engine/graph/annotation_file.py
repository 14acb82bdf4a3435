"""The ``annotations`` entry of a project file: frames and subgraphs as JSON.

```
"annotations": {
  "frames": [{"id": "frame1", "title": "Struts", "comment": "...", "rect": [x, y, w, h],
              "colour": [r, g, b]}],
  "subgraphs": [{"id": "sub1", "name": "Strut", "members": ["v1", "e1"],
                 "exposed": [{"node": "v1", "param": "position", "label": "end"}],
                 "collapsed": false}]
}
```

Optional: a file without it has none.  A malformed entry refuses the file
with `AnnotationsInvalid` naming the field (``annotations.frames[0].rect``).
"""

from __future__ import annotations

from typing import Any

from .annotations import Annotations, ExposedParam, Frame, Subgraph
from .errors import GraphError


class AnnotationsInvalid(ValueError):
    """`where` in the project data (a JSON location) and the `reason`."""

    def __init__(self, where: str, reason: str):
        super().__init__(f"{where}: {reason}")
        self.where = where
        self.reason = reason


def annotations_to_dict(ann: Annotations) -> dict[str, Any]:
    return {
        "frames": [{"id": f.id, "title": f.title, "comment": f.comment, "rect": list(f.rect),
                    "colour": list(f.colour)} for f in ann.frames.values()],
        "subgraphs": [{"id": s.id, "name": s.name, "members": list(s.members),
                       "exposed": [{"node": e.node_id, "param": e.param, "label": e.label} for e in s.exposed],
                       "collapsed": s.collapsed} for s in ann.subgraphs.values()],
    }


def _kind(v: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "true or false", int: "a number",
            float: "a number", type(None): "null"}.get(type(v), type(v).__name__)


def _need(cond: bool, where: str, expected: str, got: Any) -> None:
    if not cond:
        raise AnnotationsInvalid(where, f"expected {expected}, got {_kind(got)} {got!r}"[:300])


def read_annotations(data: Any, ann: Annotations, where: str = "annotations") -> None:
    """Fill the empty `ann` (of a document whose nodes are loaded) from `data`;
    AnnotationsInvalid naming the field when anything is malformed."""
    _need(isinstance(data, dict), where, "an object", data)
    unknown = sorted(set(data) - {"frames", "subgraphs"})
    if unknown:
        raise AnnotationsInvalid(f"{where}.{unknown[0]}", "unknown entry; expected frames or subgraphs")
    frames = data.get("frames", [])
    _need(isinstance(frames, list), f"{where}.frames", "a list", frames)
    for i, f in enumerate(frames):
        at = f"{where}.frames[{i}]"
        _need(isinstance(f, dict), at, "an object", f)
        frame = Frame(_text(f, "id", at, None), _text(f, "title", at, "Frame"), _text(f, "comment", at, ""),
                      f.get("rect", (0.0, 0.0, 300.0, 200.0)), f.get("colour", Frame.colour))
        _add(lambda: ann._raw_add_frame(frame), at, frame.id, ann.frames)
    subs = data.get("subgraphs", [])
    _need(isinstance(subs, list), f"{where}.subgraphs", "a list", subs)
    for i, s in enumerate(subs):
        at = f"{where}.subgraphs[{i}]"
        _need(isinstance(s, dict), at, "an object", s)
        members = s.get("members", [])
        _need(isinstance(members, list) and all(isinstance(m, str) for m in members), f"{at}.members",
              "a list of node ids", members)
        exposed = s.get("exposed", [])
        _need(isinstance(exposed, list), f"{at}.exposed", "a list", exposed)
        entries = []
        for k, e in enumerate(exposed):
            e_at = f"{at}.exposed[{k}]"
            _need(isinstance(e, dict), e_at, "an object", e)
            entries.append(ExposedParam(_text(e, "node", e_at, None), _text(e, "param", e_at, None),
                                        _text(e, "label", e_at, "")))
        collapsed = s.get("collapsed", False)
        _need(isinstance(collapsed, bool), f"{at}.collapsed", "true or false", collapsed)
        sub = Subgraph(_text(s, "id", at, None), _text(s, "name", at, "Subgraph"), tuple(members),
                       tuple(entries), collapsed)
        _add(lambda: ann._raw_add_subgraph(sub), at, sub.id, ann.subgraphs)


def _text(obj: dict, key: str, at: str, default: str | None) -> str:
    value = obj.get(key, default)
    _need(isinstance(value, str), f"{at}.{key}", "a string", value)
    return value


def _add(add, at: str, item_id: str, present: dict) -> None:
    if item_id in present:
        raise AnnotationsInvalid(f"{at}.id", f"id {item_id!r} is used twice")
    try:
        add()
    except GraphError as exc:
        raise AnnotationsInvalid(f"{at}.{exc.where or 'id'}", str(exc)) from None
