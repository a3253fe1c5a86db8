"""The one YAML reader of user input (preset, scenario, parameter and controller files).

PyYAML's ``safe_load`` keeps the last of two equal keys in a mapping, so a file that sets
``dtau`` twice runs with the second value and says nothing. This loader refuses a repeated
key as a YAML error naming the key and both lines (every reader already turns a YAML error
into its one line naming the file). A merge (``<<: *base``) may still be overridden: only
keys written out in the same mapping count. ROS-free.
"""

from __future__ import annotations

from typing import Any

import yaml
from yaml.constructor import ConstructorError
from yaml.nodes import MappingNode

MERGE_TAG = "tag:yaml.org,2002:merge"


class UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key given twice in one mapping."""


def _construct_mapping(loader: UniqueKeyLoader, node: MappingNode, deep: bool = False
                       ) -> dict[Any, Any]:
    seen: dict[Any, Any] = {}
    for key_node, _value in node.value:
        if key_node.tag == MERGE_TAG:
            continue
        key = loader.construct_object(key_node, deep=True)
        try:
            first = seen.get(key)
        except TypeError:                     # an unhashable key: PyYAML's own error follows
            continue
        if first is not None:
            raise ConstructorError("while constructing a mapping", node.start_mark,
                                   f"found the key {key!r} twice (first at line "
                                   f"{first.line + 1}); a key is given once",
                                   key_node.start_mark)
        seen[key] = key_node.start_mark
    return loader.construct_mapping(node, deep=deep)


UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                _construct_mapping)


def load_yaml(text: Any) -> Any:
    """``yaml.safe_load(text)``, but a key given twice in a mapping is a ``yaml.YAMLError``."""
    return yaml.load(text, Loader=UniqueKeyLoader)
