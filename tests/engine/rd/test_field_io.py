"""Field import: npz / vti round trips, files written by VTK itself, and refusals."""

import numpy as np
import pytest

from engine.rd.field_io import FieldFileError, RDFields, load_fields, save_fields
from engine.rd.regularise import orthonormalise


def _fields(grid, rng):
    d = len(grid)
    a = rng.normal(size=grid + (d, d))
    return RDFields(rho=rng.uniform(size=grid), sigma=a + np.swapaxes(a, -1, -2),
                    rotation=orthonormalise(rng.normal(size=grid + (d, d))), gamma=rng.uniform(size=grid),
                    spacing=tuple(0.5 + np.arange(d)), origin=tuple(-1.0 * np.arange(d)))


def _assert_same(a, b):
    for name in ("rho", "sigma", "rotation", "gamma"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0, atol=1e-15)
    assert a.spacing == pytest.approx(b.spacing) and a.origin == pytest.approx(b.origin)


@pytest.mark.parametrize("grid", [(5, 7), (3, 4, 6)])
@pytest.mark.parametrize("suffix, encoding", [(".npz", "base64"), (".vti", "base64"), (".vti", "ascii")])
def test_round_trip(tmp_path, grid, suffix, encoding):
    f = _fields(grid, np.random.default_rng(1))
    path = tmp_path / f"fields{suffix}"
    save_fields(path, f, encoding=encoding)
    back = load_fields(path)
    _assert_same(back, f)
    assert back.source == str(path) and not back.rho.flags.writeable


def _vtk_image(npts, arrays, point_data=False):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData

    img = vtkImageData()
    img.SetDimensions(*npts)
    img.SetSpacing(0.25, 0.5, 2.0)
    img.SetOrigin(1.0, 2.0, 3.0)
    target = img.GetPointData() if point_data else img.GetCellData()
    for name, a in arrays.items():
        v = numpy_to_vtk(np.ascontiguousarray(a), deep=True)
        v.SetName(name)
        target.AddArray(v)
    return img


def _vtk_write(img, path, mode, compress, header64, encode=True):
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

    w = vtkXMLImageDataWriter()
    w.SetFileName(str(path))
    w.SetInputData(img)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    w.SetEncodeAppendedData(encode)
    if compress:
        w.SetCompressorTypeToZLib()
    else:
        w.SetCompressorTypeToNone()
    if header64:
        w.SetHeaderTypeToUInt64()
    assert w.Write() == 1


@pytest.mark.parametrize("mode, compress, header64, encode", [
    ("ascii", False, False, True), ("binary", False, False, True), ("binary", False, True, True),
    ("binary", True, False, True), ("appended", False, False, False), ("appended", False, True, True),
    ("appended", True, True, True), ("appended", True, False, False)])
def test_reads_vti_written_by_vtk_3d(tmp_path, mode, compress, header64, encode):
    pytest.importorskip("vtkmodules")
    rng = np.random.default_rng(4)
    nx, ny, nz = 5, 4, 3                       # cells
    rho = rng.uniform(size=(nz, ny, nx))
    a = rng.normal(size=(nz, ny, nx, 3, 3))
    sigma = a + np.swapaxes(a, -1, -2)
    # VTK's 6-component symmetric tensor order: xx, yy, zz, xy, yz, xz; x runs fastest
    six = np.stack([sigma[..., 0, 0], sigma[..., 1, 1], sigma[..., 2, 2], sigma[..., 0, 1],
                    sigma[..., 1, 2], sigma[..., 0, 2]], -1).reshape(-1, 6)
    gamma = rng.uniform(size=(nz, ny, nx)).astype(np.float32)
    img = _vtk_image((nx + 1, ny + 1, nz + 1), {"rho": rho.reshape(-1), "sigma": six,
                                                 "gamma": gamma.reshape(-1), "other": np.arange(60)})
    path = tmp_path / "vtk.vti"
    _vtk_write(img, path, mode, compress, header64, encode)
    f = load_fields(path)
    tol = 1e-12 if mode != "ascii" else 1e-9
    np.testing.assert_allclose(f.rho, rho, atol=tol)
    np.testing.assert_allclose(f.sigma, sigma, atol=tol * 10)
    np.testing.assert_allclose(f.gamma, gamma, atol=1e-6)
    assert f.spacing == (0.25, 0.5, 2.0) and f.origin == (1.0, 2.0, 3.0)


def test_reads_2d_point_data_and_rotation_from_vtk(tmp_path):
    pytest.importorskip("vtkmodules")
    rng = np.random.default_rng(6)
    nx, ny = 6, 4                              # points
    rho = rng.uniform(size=(ny, nx))
    rot = orthonormalise(rng.normal(size=(ny, nx, 2, 2)))
    img = _vtk_image((nx, ny, 1), {"rho": rho.reshape(-1), "R": rot.reshape(-1, 4)}, point_data=True)
    path = tmp_path / "pts.vti"
    _vtk_write(img, path, "binary", True, False)
    f = load_fields(path)
    assert f.ndim == 2 and f.spacing == (0.25, 0.5)
    np.testing.assert_allclose(f.rho, rho, atol=1e-15)
    np.testing.assert_allclose(f.rotation, rot, atol=1e-15)    # row-major components
    assert f.sigma is None and f.gamma is None


def _save_npz(path, **arrays):
    np.savez(path, **arrays)
    return path


def test_missing_rho_is_named(tmp_path):
    path = _save_npz(tmp_path / "x.npz", density=np.ones((3, 3)))
    with pytest.raises(FieldFileError, match=r"x\.npz: array 'rho': missing.*density"):
        load_fields(path)


def test_shape_mismatch_is_named(tmp_path):
    path = _save_npz(tmp_path / "x.npz", rho=np.ones((3, 4)), gamma=np.zeros((4, 3)))
    with pytest.raises(FieldFileError, match=r"x\.npz: array 'gamma': shape \(4, 3\) does not match"):
        load_fields(path)
    path = _save_npz(tmp_path / "y.npz", rho=np.ones((3, 4)), sigma=np.zeros((3, 4, 3, 3)))
    with pytest.raises(FieldFileError, match=r"array 'sigma': shape \(3, 4, 3, 3\)"):
        load_fields(path)


def test_nan_is_named_with_its_cell(tmp_path):
    sigma = np.zeros((3, 4, 2, 2))
    sigma[2, 1, 1, 1] = np.nan
    path = _save_npz(tmp_path / "x.npz", rho=np.ones((3, 4)), sigma=sigma)
    with pytest.raises(FieldFileError, match=r"array 'sigma': has a NaN .* \[y=2, x=1\]"):
        load_fields(path)
    rho = np.ones((2, 3, 4))
    rho[1, 0, 3] = np.inf
    path = _save_npz(tmp_path / "r.npz", rho=rho)
    with pytest.raises(FieldFileError, match=r"array 'rho': NaN or infinite value at cell \[z=1, y=0, x=3\]"):
        load_fields(path)


def test_out_of_range_and_bad_rotation_refused(tmp_path):
    path = _save_npz(tmp_path / "x.npz", rho=np.full((3, 3), 1.2))
    with pytest.raises(FieldFileError, match=r"array 'rho': values must lie in \[0, 1\]"):
        load_fields(path)
    r = np.tile(np.eye(2), (3, 3, 1, 1))
    r[1, 2] = [[1.0, 1.0], [0.0, 1.0]]
    path = _save_npz(tmp_path / "r.npz", rho=np.ones((3, 3)), R=r)
    with pytest.raises(FieldFileError, match=r"array 'R': columns are not orthonormal .* \[y=1, x=2\]"):
        load_fields(path)


def test_slightly_asymmetric_sigma_warns_naming_the_file(tmp_path):
    sigma = np.tile(np.array([[2.0, 1.0], [1.0, 3.0]]), (2, 2, 1, 1))
    sigma[0, 0, 0, 1] += 1e-7
    path = _save_npz(tmp_path / "x.npz", rho=np.ones((2, 2)), sigma=sigma)
    with pytest.warns(UserWarning, match=r"x\.npz: array 'sigma'"):
        f = load_fields(path)
    np.testing.assert_array_equal(f.sigma, np.swapaxes(f.sigma, -1, -2))


def test_unreadable_and_unsupported_files(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(FieldFileError, match=r"bad\.npz: cannot read"):
        load_fields(bad)
    with pytest.raises(FieldFileError, match="must end in .npz or .vti"):
        load_fields(tmp_path / "x.h5")
    with pytest.raises(FieldFileError, match="no such file"):
        load_fields(tmp_path / "absent.vti")
    vti = tmp_path / "bad.vti"
    vti.write_text('<VTKFile type="ImageData"><ImageData WholeExtent="0 2 0 2 0 0"><Piece Extent="0 2 0 2 0 0">'
                   '<CellData><DataArray type="Float64" Name="rho" format="ascii">0 1 0</DataArray>'
                   '<DataArray type="Float64" Name="sigma" NumberOfComponents="5" format="ascii">'
                   + " 0" * 20 + '</DataArray></CellData></Piece></ImageData></VTKFile>')
    with pytest.raises(FieldFileError, match=r"bad\.vti: array 'rho': cannot decode \(holds 3 values; expected 4"):
        load_fields(vti)
    vti.write_text(vti.read_text().replace("0 1 0<", "0 1 0 1<"))
    with pytest.raises(FieldFileError, match=r"array 'sigma': has 5 components"):
        load_fields(vti)
    vti.write_text('<VTKFile type="PolyData"></VTKFile>')
    with pytest.raises(FieldFileError, match="ImageData"):
        load_fields(vti)
