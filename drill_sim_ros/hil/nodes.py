"""The asyncua nodes of a rig object (issue 53): values as Variants, the standard properties
(EngineeringUnits, EURange), Descriptions, the variable types a PLC project expects
(AnalogItemType, AnalogUnitType), the enumerations (``RigStatus``, ``DriveModeEnum``) with
their EnumStrings, and the subtree that ``--export-nodeset`` writes."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone
from enum import IntEnum
from typing import Any

from asyncua import Server, ua
from asyncua.common.structures104 import new_enum, new_enum_field

from drill_sim_ros.hil.address_space import (
    ENUMERATIONS,
    UNECE_URI,
    Variable,
    unece_unit_id,
)

SIM_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)


def variant(variable: Variable, value: Any) -> ua.Variant:
    return ua.Variant(value, getattr(ua.VariantType, variable.type_name))


def eu_information(variable: Variable) -> ua.EUInformation:
    unit = variable.unit
    return ua.EUInformation(NamespaceUri=UNECE_URI, UnitId=unece_unit_id(unit.code),
                            DisplayName=ua.LocalizedText(unit.symbol),
                            Description=ua.LocalizedText(unit.description))


def sim_timestamp(time_ns: int) -> datetime:
    """The source timestamp of a sample: its simulated time after :data:`SIM_EPOCH`."""
    return SIM_EPOCH + timedelta(microseconds=time_ns / 1000)


def range_variant(low_high: tuple[float, float]) -> ua.Variant:
    return ua.Variant(ua.Range(*low_high), ua.VariantType.ExtensionObject)


async def add_property(node: Any, name: str, value: ua.Variant, data_type: int) -> Any:
    """A standard property (BrowseName in namespace 0) of ``node``, NodeId ``<node>.<name>``."""
    index = node.nodeid.NamespaceIndex
    return await node.add_property(ua.NodeId(f"{node.nodeid.Identifier}.{name}", index),
                                   ua.QualifiedName(name, 0), value,
                                   datatype=ua.NodeId(data_type))


async def enumeration(server: Server, index: int, members: type[IntEnum]) -> ua.NodeId:
    """The Enumeration DataType ``members`` (BrowseName and NodeId its class name, in namespace
    ``index``), with its Description, its EnumDefinition and EnumStrings, as
    :data:`~.address_space.ENUMERATIONS` describes it."""
    description, meanings = ENUMERATIONS[members]
    name = members.__name__
    fields = [new_enum_field(member.name, meanings[member]) for member in members]
    data_type = await new_enum(server, ua.NodeId(name, index), ua.QualifiedName(name, index),
                               fields)
    await describe(data_type, description)
    await data_type.add_property(ua.NodeId(f"{name}.EnumStrings", index),
                                 ua.QualifiedName("EnumStrings", 0), ua.Variant(
        [ua.LocalizedText(member.name) for member in members],
        ua.VariantType.LocalizedText), datatype=ua.NodeId(ua.ObjectIds.LocalizedText))
    return data_type.nodeid


async def describe(node: Any, text: str) -> None:
    await node.write_attribute(ua.AttributeIds.Description, ua.DataValue(
        ua.Variant(ua.LocalizedText(text), ua.VariantType.LocalizedText)))


async def retype(node: Any, type_id: int) -> None:
    """Make ``node`` (a BaseDataVariableType) an instance of the variable type ``type_id``
    (AnalogItemType: EURange and EngineeringUnits; AnalogUnitType: EngineeringUnits)."""
    await node.delete_reference(ua.NodeId(ua.ObjectIds.BaseDataVariableType),
                                ua.ObjectIds.HasTypeDefinition, bidirectional=False)
    await node.add_reference(ua.NodeId(type_id), ua.ObjectIds.HasTypeDefinition,
                             bidirectional=False)


async def subtree(node: Any) -> list[Any]:
    """``node`` and everything under it (children by hierarchical references, properties)."""
    nodes = [node]
    for child in await node.get_children():
        nodes += await subtree(child)
    return nodes
