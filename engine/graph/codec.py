"""One interface for the values kept in project files: a registry of codecs.

A stateful node's result is kept in the project file (``node_state``, see
`engine.graph.node_state`) as JSON.  How a value becomes JSON is not the
node's business, nor the graph core's: a codec, registered for the value's
class under the name of the port type it travels as, says it::

    register_codec(TilingValue, "Tiling", encode, decode)

``encode(value) -> dict`` gives a JSON-able dict (or None: this value cannot
be stored); ``decode(dict, inputs) ->
value`` rebuilds the value against the node's current inputs (``{port name:
value}``: e.g. the tile set a stored tiling indexes), raising ValueError when
the dict is malformed or does not fit them.  The registrations live in
``engine.nodes.codecs`` (nodes may import both the graph and the families;
the families' value modules never import the graph).

The stored dict of a node (what `encode_outputs` gives) carries no codec
name, so that project files written before codecs existed load and re-save
byte for byte: the node's declared output ports say which codec reads it.
A node with one output stores that value's dict as it is; a node with
several stores ``{port name: dict}``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterable

__all__ = ["Codec", "register_codec", "codec_for", "has_codecs", "encode_outputs", "decode_outputs"]


@dataclass(frozen=True)
class Codec:
    """How values of one class are kept in a project file.

    value_class : the class of the values (an instance of a subclass is
        encoded by the same codec).
    name : the port type the values travel as (``Port.type``).
    encode : ``encode(value) -> dict``, JSON-able, or None (not storable).
    decode : ``decode(blob, inputs) -> value``; ValueError when ``blob`` is
        malformed or does not fit the node's current ``inputs``.
    """

    value_class: type
    name: str
    encode: Callable[[Any], dict]
    decode: Callable[[dict, dict], Any]


_BY_NAME: dict[str, Codec] = {}


def register_codec(value_class: type, name: str, encode: Callable[[Any], dict],
                   decode: Callable[[dict, dict], Any]) -> Codec:
    """Register how values of ``value_class`` (port type ``name``) are stored.

    Registering the same class under the same name again replaces the codec
    (a module reloaded); another class under a taken name raises ValueError.
    """
    if not isinstance(value_class, type) or not name:
        raise ValueError(f"register_codec: expected a class and a port type name; "
                         f"got {value_class!r}, {name!r}")
    old = _BY_NAME.get(name)
    if old is not None and old.value_class is not value_class:
        raise ValueError(f"port type {name!r} already has a codec for {old.value_class.__name__}")
    codec = Codec(value_class, name, encode, decode)
    _BY_NAME[name] = codec
    return codec


def codec_for(port_type: str) -> Codec | None:
    """The codec registered for ``port_type``, or None."""
    return _BY_NAME.get(port_type)


def has_codecs(ports: Iterable) -> bool:
    """Whether every port (``engine.graph.schema.Port``) has a codec for its type
    (and there is at least one port)."""
    ports = tuple(ports)
    return bool(ports) and all(p.type in _BY_NAME for p in ports)


def encode_outputs(outputs: dict[str, Any], ports: Iterable) -> dict | None:
    """A node's outputs as the JSON-able dict kept in the project file.

    outputs : ``{port name: value}`` as the node's evaluate returned them.
    ports : the node type's output ports (``NodeType.outputs``).

    Returns None when some port's type has no codec or a codec gives None for
    its value (the node's result is then not kept).  Raises TypeError when a
    value is not of its codec's class.
    """
    ports = tuple(ports)
    if not has_codecs(ports):
        return None
    blobs = {}
    for port in ports:
        codec = _BY_NAME[port.type]
        value = outputs[port.name]
        if not isinstance(value, codec.value_class):
            raise TypeError(f"output {port.name!r}: expected {codec.value_class.__name__}, "
                            f"got {type(value).__name__}")
        blob = codec.encode(value)
        if blob is None:
            return None
        blobs[port.name] = blob
    return blobs[ports[0].name] if len(ports) == 1 else blobs


def decode_outputs(blob: dict, inputs: dict[str, Any], ports: Iterable) -> dict[str, Any]:
    """The outputs ``{port name: value}`` rebuilt from `encode_outputs`'s dict
    against the node's current ``inputs``.

    Raises ValueError when a port's type has no codec, the dict is malformed
    or a codec finds it does not fit the inputs.
    """
    ports = tuple(ports)
    missing = [p.type for p in ports if p.type not in _BY_NAME]
    if missing or not ports:
        raise ValueError(f"no codec stores values of port type(s) {missing or 'none'}")
    if not isinstance(blob, dict):
        raise ValueError(f"expected an object, got {type(blob).__name__}")
    if len(ports) == 1:
        parts = {ports[0].name: blob}
    else:
        absent = [p.name for p in ports if not isinstance(blob.get(p.name), dict)]
        if absent:
            raise ValueError(f"no stored value for output(s) {absent}")
        parts = {p.name: blob[p.name] for p in ports}
    out = {}
    for port in ports:
        codec = _BY_NAME[port.type]
        value = codec.decode(parts[port.name], inputs)
        if not isinstance(value, codec.value_class):
            raise ValueError(f"output {port.name!r}: the {port.type} codec gave a {type(value).__name__}")
        out[port.name] = value
    return out
