# Types of the native module (crates/odc-python/src), for editors and type checkers.
from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

_Path = Union[str, PathLike]
Diagnostic = Dict[str, Any]
Value = Union[None, bool, int, float, str, bytes, Tuple[int, int], "NodeIdPlus", "Invalid"]

__version__: str

class NodeIdPlus:
    offset: int
    def __init__(self, offset: int) -> None: ...
    def resolve(self, node_id: int) -> int: ...

class Invalid:
    text: str
    def __init__(self, text: str) -> None: ...

class SubObject:
    index: int
    sub_index: int
    name: str
    data_type: int
    data_type_name: str
    access: str
    pdo_mapping: bool
    default: Value
    default_raw: Optional[str]
    low_limit: Value
    high_limit: Value
    parameter_value: Value
    parameter_value_raw: Optional[str]
    bit_size: Optional[int]
    denotation: Optional[str]
    extra: Dict[str, str]

class Object:
    index: int
    name: str
    kind: str
    subs: Dict[int, SubObject]
    compact_sub_obj: Optional[int]
    obj_flags: Optional[int]
    in_file: bool
    extra: Dict[str, str]
    def __getitem__(self, sub: int) -> SubObject: ...

class PdoEntry:
    index: int
    sub: int
    bits: int
    name: Optional[str]

class Pdo:
    direction: str
    mapping_index: int
    comm_index: Optional[int]
    name: str
    cob_id: Union[None, int, NodeIdPlus]
    transmission_type: Optional[int]
    inhibit_time: Optional[int]
    event_timer: Optional[int]
    sync_manager: Optional[int]
    entries: List[PdoEntry]

class Identity:
    vendor_name: Optional[str]
    vendor_number: Optional[int]
    product_name: Optional[str]
    product_number: Optional[int]
    revision_number: Optional[int]
    order_code: Optional[str]
    baud_rates: List[int]
    simple_boot_up_master: Optional[bool]
    simple_boot_up_slave: Optional[bool]
    granularity: Optional[int]
    dynamic_channels_supported: Optional[int]
    group_messaging: Optional[bool]
    nr_of_rx_pdo: Optional[int]
    nr_of_tx_pdo: Optional[int]
    lss_supported: Optional[bool]

class Device:
    format: Optional[str]
    identity: Identity
    objects: Dict[int, Object]
    pdos: List[Pdo]
    dummy_usage: List[int]
    comments: List[str]
    node_id: Optional[int]
    baud_rate: Optional[int]
    diagnostics: List[Diagnostic]
    def __getitem__(self, index: int) -> Object: ...

def load(path: _Path, *, allow: Sequence[str] = ..., warn: Sequence[str] = ...,
         deny: Sequence[str] = ..., strict: bool = ..., config: Optional[_Path] = ...,
         device: Optional[str] = ..., data: Optional[bytes] = ...) -> Device: ...
def check(path: _Path, *, allow: Sequence[str] = ..., warn: Sequence[str] = ...,
          deny: Sequence[str] = ..., strict: bool = ..., config: Optional[_Path] = ...,
          device: Optional[str] = ...) -> List[Diagnostic]: ...
def convert(path: _Path, to: str, *, allow: Sequence[str] = ..., warn: Sequence[str] = ...,
            deny: Sequence[str] = ..., strict: bool = ..., config: Optional[_Path] = ...,
            device: Optional[str] = ...) -> str: ...
def doc(path: _Path, format: str = ..., *, allow: Sequence[str] = ...,
        warn: Sequence[str] = ..., deny: Sequence[str] = ..., strict: bool = ...,
        config: Optional[_Path] = ..., device: Optional[str] = ...) -> str: ...
def diff_json(a: _Path, b: _Path, *, ignore_names: bool = ..., ignore_comments: bool = ...,
              ignore_defaults: bool = ..., device_a: Optional[str] = ...,
              device_b: Optional[str] = ...) -> str: ...
def load_canopen(path: _Path, *, node_id: Optional[int] = ..., allow: Sequence[str] = ...,
                 warn: Sequence[str] = ..., deny: Sequence[str] = ..., strict: bool = ...,
                 data: Optional[bytes] = ..., template: Dict[str, Any],
                 containers: Sequence[Tuple[str, type]], cls: type,
                 new: Any) -> Tuple[Device, List[Tuple[int, str, str, Optional[str], List[Any]]],
                                    Optional[int]]: ...
