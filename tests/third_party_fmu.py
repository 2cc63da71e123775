"""Build the C FMU of tests/fmus/third_party/ (an FMI 2.0 co-simulation FMU not made by pythonfmu):
gcc against fmpy's FMI headers, zipped with its hand-written modelDescription.xml."""
import shutil
import subprocess
import zipfile
from pathlib import Path

SOURCE = Path(__file__).resolve().parent / "fmus" / "third_party"
MODEL_IDENTIFIER = "c_attitude_pd"


def build_c_fmu(folder: Path) -> Path:
    """Compile and package ``CAttitudePD.fmu`` into ``folder``; returns its path."""
    import fmpy

    headers = Path(fmpy.__file__).parent / "c-code"
    gcc = shutil.which("gcc") or shutil.which("cc")
    if gcc is None:
        raise RuntimeError("no C compiler (gcc or cc) on PATH: the third-party FMU tests need one")
    folder = Path(folder)
    binary = folder / f"{MODEL_IDENTIFIER}{fmpy.sharedLibraryExtension}"
    subprocess.run([gcc, "-shared", "-fPIC", "-O2", "-std=c99", "-Wall", "-Wno-unused-parameter",
                    "-I", str(headers), str(SOURCE / "attitude_pd.c"), "-o", str(binary), "-lm"],
                   check=True, capture_output=True, text=True)
    fmu = folder / "CAttitudePD.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(SOURCE / "modelDescription.xml", "modelDescription.xml")
        z.write(binary, f"binaries/{fmpy.platform}/{binary.name}")
        z.write(SOURCE / "attitude_pd.c", "sources/attitude_pd.c")
    return fmu
