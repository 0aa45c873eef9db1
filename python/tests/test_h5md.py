"""granmem's trajectory store against the H5MD 1.1 specification and its units module
(nongnu.org/h5md: "H5MD metadata", "Time-dependent data", "Simulation box", "Modules",
units module "Unit string"), checked with h5py, an independent reader; and H5MD files
written by h5py as another producer would, without granmem's conventions, read by granmem."""
import re

import h5py
import numpy as np
import pytest

import granmem

from test_simulate import TINY

# A unit string: factors separated by one space, each a number or an SI symbol with an
# optional prefix, and an optional signed integer power (units module, "Unit string").
PREFIX = "(E|P|T|G|M|k|h|da|d|c|m|u|n|p|f|a)?"
SYMBOL = "(m|g|s|A|K|mol|cd|rad|sr|Hz|N|Pa|J|W|C|V|F|ohm|S|Wb|T|H|lm|lx|Bq|Gy|Sv|kat)"
FACTOR = re.compile(rf"^([0-9]+(\.[0-9]+)?|{PREFIX}{SYMBOL})([+-][1-9][0-9]*)?$")


def fixed_length_scalar_string(attrs, name):
    """The attribute's value, after checking it is a fixed-length string of scalar space."""
    attr_id = attrs.get_id(name)
    assert attr_id.get_type().get_class() == h5py.h5t.STRING, name
    assert not attr_id.get_type().is_variable_str(), f"{name} is a variable-length string"
    assert attr_id.shape == (), f"{name} is not scalar"
    value = attrs[name]
    return value.decode() if isinstance(value, bytes) else str(value)


def check_unit(dataset):
    unit = fixed_length_scalar_string(dataset.attrs, "unit")
    assert dataset.attrs.get_id("unit").get_type().get_cset() == h5py.h5t.CSET_ASCII
    factors = unit.split(" ")
    assert all(FACTOR.match(f) for f in factors), f"{dataset.name}: unit '{unit}'"
    assert [f for f in factors if f[0].isdigit()] in ([], factors[:1]), unit


def check_element(group, frames=None):
    """A time-dependent element: value [T, ...], step [T] increasing, time [T] if present."""
    value, step = group["value"], group["step"]
    assert step.dtype.kind == "i" and step.ndim == 1 and len(step) == value.shape[0]
    assert np.all(np.diff(step[()]) > 0), f"{group.name}/step is not increasing"
    assert "unit" not in step.attrs, f"{group.name}/step has a unit"
    if "time" in group:
        time = group["time"]
        assert time.dtype.kind in "fi" and time.shape == step.shape
        assert np.all(np.diff(time[()]) >= 0)
        if "unit" in time.attrs:
            check_unit(time)
    if "unit" in value.attrs:
        check_unit(value)
    if frames is not None:
        assert value.shape[0] == frames


def check_conforms(path):
    with h5py.File(path, "r") as f:
        version = f["h5md"].attrs["version"]
        assert version.dtype.kind == "i" and list(version) == [1, 1]
        assert fixed_length_scalar_string(f["h5md/author"].attrs, "name")
        assert fixed_length_scalar_string(f["h5md/creator"].attrs, "name") == "granmem"
        assert fixed_length_scalar_string(f["h5md/creator"].attrs, "version")
        for module in f["h5md/modules"].values():
            assert list(module.attrs["version"]) == [1, 0] and module.attrs["version"].dtype.kind == "i"
        units = f["h5md/modules/units"]
        assert fixed_length_scalar_string(units.attrs, "system") == "SI"
        for name, particles in f["particles"].items():
            box = particles["box"]
            assert box.attrs["dimension"] == 3 and box.attrs["dimension"].dtype.kind == "i"
            boundary = box.attrs.get_id("boundary")
            assert not boundary.get_type().is_variable_str() and boundary.shape == (3,)
            assert all(b in (b"none", b"periodic") for b in box.attrs["boundary"])
            if "edges" in box:
                assert box["edges"].shape == (3,)
            position = particles["position"]
            assert position["value"].ndim == 3 and position["value"].shape[2] == 3
            frames = position["value"].shape[0]
            check_element(position, frames)
            for element in ("axis", "orientation", "hole_contact"):
                if element in particles:
                    check_element(particles[element], frames)
            ids = particles["id"][()]
            assert ids.dtype.kind == "i" and len(np.unique(ids)) == len(ids)
            assert ids.shape == (position["value"].shape[1],)
        for name, observable in f.get("observables", {}).items():
            check_element(observable)

        def every_unit(name, obj):
            if isinstance(obj, h5py.Dataset) and "unit" in obj.attrs:
                check_unit(obj)
        f.visititems(every_unit)


def test_a_simulated_run_conforms(tmp_path):
    granmem.simulate(out=tmp_path / "run.h5", cycles=2, **TINY)
    check_conforms(tmp_path / "run.h5")
    with h5py.File(tmp_path / "run.h5", "r") as f:
        assert f["particles/grains/position/value"].attrs["unit"] == b"m"
        assert f["particles/grains/position/time"].attrs["unit"] == b"s"
        assert f["observables/wall_force/value"].attrs["unit"] == b"N"
        assert "unit" not in f["observables/packing_fraction/value"].attrs  # dimensionless


def test_the_author_set_is_recorded(tmp_path):
    granmem.set_author("A. Lab")
    try:
        granmem.simulate(out=tmp_path / "run.h5", cycles=1, **TINY)
    finally:
        granmem.set_author("")  # the login name again, for the other tests
    with h5py.File(tmp_path / "run.h5", "r") as f:
        assert f["h5md/author"].attrs["name"] == b"A. Lab"


def test_a_tracked_run_in_voxels_and_cycles_conforms(tmp_path, cli):
    (tmp_path / "t.csv").write_text("frame,particle,x,y,z,ax,ay,az,ep,axis_error\n"
                                    "0,1,1,2,3,0,0,1,0.03,0.01\n0,2,4,5,6,1,0,0,0.02,0.02\n"
                                    "1,1,1.5,2,3,0,0,1,0.03,0.01\n1,2,4,5,6.5,1,0,0,0.02,\n")
    cli("import", "t.csv", "--out", "run.h5", "--container", "0,0,0,10,10,10")
    check_conforms(tmp_path / "run.h5")
    with h5py.File(tmp_path / "run.h5", "r") as f:
        # voxel and cycle are no unit symbols: granmem's own attribute keeps them.
        position = f["particles/grains/position"]
        assert "unit" not in position["value"].attrs and "unit" not in position["time"].attrs
        assert position["value"].attrs["granmem_unit"] == b"voxel"
        assert position["time"].attrs["granmem_unit"] == b"cycle"
        # a scan's standard errors: positions' unit, and rad (an SI unit) for the axis'
        assert f["particles/grains/position_error/value"].attrs["granmem_unit"] == b"voxel"
        assert f["particles/grains/axis_error/value"].attrs["unit"] == b"rad"
        assert f["particles/grains/axis_error/value"].shape == (2, 2)
    run = granmem.read_run(tmp_path / "run.h5")
    assert run["length_unit"] == "voxel" and run["time_unit"] == "cycle"


def write_foreign(path, strings="fixed"):
    """An H5MD file as another producer writes it: a particles group 'all', no unit
    attributes, a fixed interval (a scalar step with an offset), no time, none of granmem's
    extras; strings fixed-length or variable-length ASCII (H5MD 1.0's way)."""
    positions = np.array([[[0.01, 0.02, 0.03], [0.04, 0.05, 0.06]],
                          [[0.011, 0.02, 0.03], [0.04, 0.05, 0.062]],
                          [[0.012, 0.02, 0.03], [0.04, 0.05, 0.064]]])
    with h5py.File(path, "w") as f:
        h5md = f.create_group("h5md")
        h5md.attrs["version"] = np.array([1, 1], dtype=np.int32)
        vlen = h5py.string_dtype("ascii")
        for group, attrs in (("author", {"name": "A. Nother"}),
                             ("creator", {"name": "otherMD", "version": "2.0"})):
            g = h5md.create_group(group)
            for key, value in attrs.items():
                if strings == "fixed":
                    g.attrs[key] = np.bytes_(value)
                else:
                    g.attrs.create(key, value, dtype=vlen)
        particles = f.create_group("particles/all")
        box = particles.create_group("box")
        box.attrs["dimension"] = np.int32(3)
        box.attrs["boundary"] = np.array([b"none"] * 3)
        box.create_dataset("edges", data=[0.1, 0.1, 0.1])
        position = particles.create_group("position")
        position.create_dataset("value", data=positions)
        step = position.create_dataset("step", data=np.int64(100))
        step.attrs["offset"] = np.int64(1000)
        particles.create_dataset("id", data=np.array([7, 3], dtype=np.int64))
    return positions


@pytest.mark.parametrize("strings", ["fixed", "variable"])
def test_a_file_of_another_writer_is_read(tmp_path, cli, strings):
    positions = write_foreign(tmp_path / "other.h5", strings)
    run = granmem.read_run(tmp_path / "other.h5")
    np.testing.assert_array_equal(run["position"], positions)
    np.testing.assert_array_equal(run["step"], [1000, 1100, 1200])  # i x step + offset
    np.testing.assert_array_equal(run["time"], [1000, 1100, 1200])  # no time: the steps
    assert run["time_unit"] == "step"
    assert run["length_unit"] == "m"  # no unit: metres, and the file's parameters say so
    assert "assumed" in run["parameters"]["h5md/length_unit"]
    np.testing.assert_array_equal(run["id"], [7, 3])
    info = cli("info", "other.h5")
    assert "otherMD 2.0" in info and "A. Nother" in info
    assert granmem.info(tmp_path / "other.h5") == info.replace("other.h5:", str(tmp_path / "other.h5") + ":", 1)
    cli("analyze", "other.h5", "--out", "a")
    table = (tmp_path / "a" / "displacements.csv").read_text().splitlines()
    assert len([row for row in table if not row.startswith("#")]) == 1 + 2 * 2
