"""ROS 2's IDL types as Cyclone DDS's Python binding declares them, shared by the test
publisher and subscriber: the names rmw gives them for DDS (module `msg::dds_`, names ending in
`_`), field for field the `.msg` definitions."""
from dataclasses import dataclass
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32, uint32, uint64, uint16, uint8, float64, sequence

@dataclass
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32

@dataclass
class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time_
    frame_id: str

@dataclass
class Vector3_(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64
    y: float64
    z: float64

@dataclass
class Vector3Stamped_(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3Stamped_"):
    header: Header_
    vector: Vector3_

@dataclass
class EventPacket_(IdlStruct, typename="event_camera_msgs::msg::dds_::EventPacket_"):
    header: Header_
    height: uint32
    width: uint32
    seq: uint64
    time_base: uint64
    encoding: str
    is_bigendian: bool
    events: sequence[uint8]

@dataclass
class Event_(IdlStruct, typename="dvs_msgs::msg::dds_::Event_"):
    x: uint16
    y: uint16
    ts: Time_
    polarity: bool

@dataclass
class EventArray_(IdlStruct, typename="dvs_msgs::msg::dds_::EventArray_"):
    header: Header_
    height: uint32
    width: uint32
    events: sequence[Event_]
