"""resolved_stream.py — read a resolved jdem scene (`build/jdem resolve`) with the particles
streamed: libyaml's event parser (PyYAML's CParser) reads the file in chunks, every top-level key
but `particles` is composed and constructed as yaml.load would, and each particle is handed to a
callback as its own small mapping and then dropped.  yaml.load of 100 000 particles took 50 s
and 1.1 GB; a million particles did not fit in memory.

    scene = read_resolved(path_or_file, on_particle)   # scene without "particles"

on_particle(scene_so_far, particle) is called in file order; scene_so_far holds the keys read
before `particles` (`jdem resolve` writes materials and interactions first).  Anchors and
aliases are refused (`jdem resolve` writes none).  Errors raise yaml.YAMLError.
"""
import yaml
from yaml import events, nodes

Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _error(event, what):
    mark = event.start_mark
    where = " (line %d, column %d)" % (mark.line + 1, mark.column + 1) if mark else ""
    return yaml.YAMLError("%s%s" % (what, where))


def _node(loader, event):
    """The node that starts with EVENT (already taken from the parser)."""
    if isinstance(event, events.AliasEvent) or getattr(event, "anchor", None):
        raise _error(event, "anchors and aliases are not part of a resolved scene")
    if isinstance(event, events.ScalarEvent):
        tag = event.tag if event.tag not in (None, "!") else loader.resolve(nodes.ScalarNode, event.value,
                                                                          event.implicit)
        return nodes.ScalarNode(tag, event.value, event.start_mark, event.end_mark, event.style)
    if isinstance(event, events.SequenceStartEvent):
        items = []
        while not loader.check_event(events.SequenceEndEvent):
            items.append(_node(loader, loader.get_event()))
        end = loader.get_event()
        tag = event.tag if event.tag not in (None, "!") else loader.resolve(nodes.SequenceNode, None, event.implicit)
        return nodes.SequenceNode(tag, items, event.start_mark, end.end_mark, event.flow_style)
    if isinstance(event, events.MappingStartEvent):
        pairs = []
        while not loader.check_event(events.MappingEndEvent):
            key = _node(loader, loader.get_event())
            pairs.append((key, _node(loader, loader.get_event())))
        end = loader.get_event()
        tag = event.tag if event.tag not in (None, "!") else loader.resolve(nodes.MappingNode, None, event.implicit)
        return nodes.MappingNode(tag, pairs, event.start_mark, end.end_mark, event.flow_style)
    raise _error(event, "unexpected YAML event %s" % type(event).__name__)


def _expect(loader, kind, what):
    event = loader.get_event()
    if not isinstance(event, kind):
        raise _error(event, what)
    return event


def read_resolved(stream, on_particle):
    loader = Loader(stream)
    try:
        _expect(loader, events.StreamStartEvent, "not a YAML stream")
        _expect(loader, events.DocumentStartEvent, "empty file: expected a resolved scene")
        _expect(loader, events.MappingStartEvent, "a resolved scene is a mapping")
        scene = {}
        while not loader.check_event(events.MappingEndEvent):
            key = loader.construct_document(_node(loader, loader.get_event()))
            if not isinstance(key, str):
                raise yaml.YAMLError("top-level key %r is not a string" % (key,))
            if key in scene:
                raise yaml.YAMLError("top-level key %r appears twice" % key)
            if key != "particles" or not loader.check_event(events.SequenceStartEvent):
                scene[key] = loader.construct_document(_node(loader, loader.get_event()))
                continue
            loader.get_event()
            count = 0
            while not loader.check_event(events.SequenceEndEvent):
                on_particle(scene, loader.construct_document(_node(loader, loader.get_event())))
                count += 1
            loader.get_event()
            scene[key] = count
        loader.get_event()
        _expect(loader, events.DocumentEndEvent, "end of the scene expected")
        if not loader.check_event(events.StreamEndEvent):
            raise yaml.YAMLError("more than one YAML document")
        return scene
    finally:
        loader.dispose()
