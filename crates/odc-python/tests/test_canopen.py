"""odc.canopen.import_od: python-canopen's classes, filled from odc's model."""

import io
import logging

import pytest

canopen = pytest.importorskip("canopen")

import odc  # noqa: E402
import odc.canopen  # noqa: E402
from test_odc import EDS  # noqa: E402


@pytest.fixture
def eds(tmp_path):
    path = tmp_path / "t.eds"
    path.write_text(EDS)
    return str(path)


def test_classes_and_values(eds):
    od = odc.canopen.import_od(eds, node_id=5)
    assert isinstance(od, canopen.ObjectDictionary)
    speed = od["Speed"]
    assert isinstance(speed, canopen.objectdictionary.ODVariable)
    assert (speed.index, speed.subindex, speed.data_type) == (0x2000, 0, 0x0003)
    assert (speed.access_type, speed.pdo_mappable) == ("rww", True)
    assert (speed.default, speed.min, speed.max) == (-1, -100, 100)
    assert (speed.unit, speed.factor) == ("rpm", 0.5)
    ident = od[0x1018]
    assert isinstance(ident, canopen.objectdictionary.ODRecord)
    assert ident["Vendor-ID"].default == 0x1234
    assert od[0x2001].default == 1.2


def test_nodeid_as_python_canopen_has_it(eds):
    cob = odc.canopen.import_od(eds, node_id=5)[0x1400][1]
    assert cob.relative is True
    assert cob.default == 0x205
    assert cob.default_raw == "$NODEID+0x200"
    unresolved = odc.canopen.import_od(eds)[0x1400][1]
    assert unresolved.relative is True and unresolved.default is None


def test_compact_array_and_dummies(eds):
    od = odc.canopen.import_od(eds)
    arr = od[0x1003]
    assert isinstance(arr, canopen.objectdictionary.ODArray)
    assert sorted(arr.subindices) == [0, 1, 2, 3, 4]
    assert arr[4].data_type == 0x0007 and arr[4].access_type == "ro"
    assert [i for i in od.indices if i < 8] == [2, 5]
    assert od["Dummy0005"].data_type == 5
    assert od.comments == "first\nsecond"
    assert od.device_information.allowed_baudrates == {250_000, 500_000}
    assert od.device_information.vendor_number == 0x1234


def test_file_like_object_and_format_errors(eds):
    with open(eds) as f:
        od = odc.canopen.import_od(f)
    assert 0x2000 in od
    buf = io.StringIO(EDS)
    buf.name = "mock.dcf"
    assert odc.canopen.import_od(buf)[0x1017].default == 8
    with pytest.raises(ValueError, match="'py'"):
        odc.canopen.import_od(__file__)
    with pytest.raises(OSError):
        odc.canopen.import_od("/nonexistent/x.eds")
    assert len(odc.canopen.import_od(None)) == 0


def test_values_that_do_not_read_are_dropped_and_logged(tmp_path, caplog):
    path = tmp_path / "bad.eds"
    path.write_text(EDS.replace("DefaultValue=0xFFFF", "DefaultValue=fast"))
    with caplog.at_level(logging.WARNING, logger="odc.canopen"):
        od = odc.canopen.import_od(str(path))
    assert od[0x2000].default is None
    assert any("F107" in r.getMessage() for r in caplog.records)
    assert any(d["code"] == "F107" for d in od.odc_diagnostics)
    with pytest.raises(odc.Refused):
        odc.canopen.import_od(str(path), deny=["F107"])


def test_remote_node_takes_the_dictionary(eds):
    od = odc.canopen.import_od(eds, node_id=5)
    node = canopen.RemoteNode(5, od)
    assert node.sdo[0x2000].od is od[0x2000]
    assert node.sdo[0x2000].od.encode_raw(-1) == b"\xff\xff"


def test_xdd_reads_as_its_eds(eds, tmp_path):
    # python-canopen reads no XDD; odc's importer gives the same dictionary for the same device.
    xdd = tmp_path / "t.xdd"
    xdd.write_text(odc.convert(eds, "xdd"))
    a, b = odc.canopen.import_od(eds, node_id=5), odc.canopen.import_od(str(xdd), node_id=5)
    assert sorted(a.indices) == sorted(b.indices)
    for index in (0x1400, 0x2000, 0x2001):
        va = a[index][1] if index == 0x1400 else a[index]
        vb = b[index][1] if index == 0x1400 else b[index]
        for attr in ("name", "data_type", "access_type", "default", "min", "max", "relative"):
            assert getattr(va, attr) == getattr(vb, attr), (hex(index), attr)
    assert b[0x1400][1].default == 0x205
