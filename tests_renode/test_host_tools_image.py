"""dcos-image, the signer and checker of controller images (docs/boot.md,
"Controller images"; docs/guide/signing-images.md), on the real firmware.

Checked against implementations we did not write: the payload is exactly
what binutils' objcopy -O binary makes of the same ELF file, OpenSSL
verifies the images' signatures, and keys OpenSSL generates sign images
the tool then verifies.
"""
import json
import os
import stat
import subprocess

import pytest

from dcoslab.board import EXIT_PASS

# On-target tests this module runs (see test_kernel_core.test_every_target_test_is_run).
IMAGE_TARGET_TESTS = ["image", "wycheproof"]

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-image")
FIRMWARE = os.path.join(REPOSITORY, "build", "486", "dcos486.elf")

HEADER_SIZE = 256
SIGNED_SIZE = 192


def run(*arguments, check_code=None):
    result = subprocess.run([TOOL, *arguments], capture_output=True, text=True, timeout=60)
    if check_code is not None:
        assert result.returncode == check_code, (
            f"dcos-image {' '.join(arguments)}: exit {result.returncode}\n{result.stdout}{result.stderr}")
    return result


@pytest.fixture
def workspace(tmp_path):
    """A key pair and the firmware signed with it as 1.2.3+7."""
    key = tmp_path / "key.pem"
    run("keygen", "-o", str(key), check_code=0)
    image = tmp_path / "firmware.dcos"
    run("sign", "-k", str(key), "--board", "isa486", "--version", "1.2.3+7", "-o", str(image), FIRMWARE,
        check_code=0)
    return tmp_path, key, tmp_path / "key.pem.pub", image


def der_signature(raw):
    """The DER form (SEQUENCE of two INTEGERs) OpenSSL takes, from r || s."""
    def integer(value):
        value = value.lstrip(b"\0") or b"\0"
        if value[0] & 0x80:
            value = b"\0" + value
        return bytes([0x02, len(value)]) + value
    body = integer(raw[:32]) + integer(raw[32:])
    return bytes([0x30, len(body)]) + body


def test_the_tool_answers_help_and_version_and_documents_its_exit_codes():
    help_text = run("--help", check_code=0).stdout
    for word in ("keygen", "sign", "verify", "info", "--json", "exit status"):
        assert word in help_text, help_text
    assert run("--version", check_code=0).stdout.startswith("dcos-image ")
    assert run("sign", "--board", "isa486", check_code=2).returncode == 2
    assert run("nonsense", check_code=2).returncode == 2


def test_keygen_keeps_the_private_key_private_and_never_overwrites_one(tmp_path):
    key = tmp_path / "signing.pem"
    out = json.loads(run("--json", "keygen", "-o", str(key), "--public", str(tmp_path / "p.pem"), check_code=0).stdout)
    assert out["private_key"] == str(key) and len(out["key_id"]) == 64
    assert stat.S_IMODE(os.stat(key).st_mode) == 0o600
    assert stat.S_IMODE(os.stat(tmp_path / "p.pem").st_mode) == 0o644
    before = key.read_bytes()
    refused = run("keygen", "-o", str(key), "--public", str(tmp_path / "p.pem"), check_code=3)
    assert "exists already" in refused.stderr
    assert key.read_bytes() == before, "the refused keygen left the key alone"
    run("keygen", "-o", str(key), "--public", str(tmp_path / "p.pem"), "--force", check_code=0)
    assert key.read_bytes() != before


def test_the_payload_is_what_objcopy_makes_of_the_firmware(workspace):
    tmp_path, _, _, image = workspace
    flat = tmp_path / "flat.bin"
    subprocess.run(["objcopy", "-O", "binary", FIRMWARE, str(flat)], check=True, timeout=60)
    data = image.read_bytes()
    assert data[HEADER_SIZE:] == flat.read_bytes()
    info = json.loads(run("--json", "info", str(image), check_code=0).stdout)
    entry = subprocess.run(["readelf", "-h", FIRMWARE], capture_output=True, text=True, check=True).stdout
    assert f"Entry point address:               {hex(info['entry'])}" in entry
    assert info["board"] == "isa486" and info["version"] == "1.2.3+7"
    assert info["payload_size"] == len(data) - HEADER_SIZE and info["payload_matches"] is True
    assert info["load_address"] == 0x100000 and info["memory_size"] >= info["payload_size"]


def test_openssl_verifies_the_signature_the_tool_made(workspace):
    tmp_path, _, public, image = workspace
    data = image.read_bytes()
    (tmp_path / "signed.bin").write_bytes(data[:SIGNED_SIZE])
    (tmp_path / "sig.der").write_bytes(der_signature(data[SIGNED_SIZE:HEADER_SIZE]))
    verified = subprocess.run(["openssl", "dgst", "-sha256", "-verify", str(public), "-signature",
                               str(tmp_path / "sig.der"), str(tmp_path / "signed.bin")],
                              capture_output=True, text=True, timeout=60)
    assert verified.returncode == 0 and "Verified OK" in verified.stdout, verified.stdout + verified.stderr
    # And OpenSSL refuses it for a header changed by one bit.
    changed = bytearray(data[:SIGNED_SIZE])
    changed[20] ^= 1
    (tmp_path / "signed.bin").write_bytes(bytes(changed))
    refused = subprocess.run(["openssl", "dgst", "-sha256", "-verify", str(public), "-signature",
                              str(tmp_path / "sig.der"), str(tmp_path / "signed.bin")],
                             capture_output=True, text=True, timeout=60)
    assert refused.returncode != 0


@pytest.mark.parametrize("generate", [
    ["ecparam", "-name", "prime256v1", "-genkey", "-noout"],          # SEC 1 "EC PRIVATE KEY"
    ["genpkey", "-algorithm", "EC", "-pkeyopt", "ec_paramgen_curve:P-256"],  # PKCS #8
])
def test_a_key_openssl_generated_signs_images(tmp_path, generate):
    key = tmp_path / "openssl.pem"
    subprocess.run(["openssl", *generate, "-out", str(key)], check=True, capture_output=True, timeout=60)
    public = tmp_path / "openssl.pub"
    subprocess.run(["openssl", "pkey", "-in", str(key), "-pubout", "-out", str(public)], check=True,
                   capture_output=True, timeout=60)
    image = tmp_path / "a.dcos"
    run("sign", "-k", str(key), "--board", "isa486", "--version", "2.0.0", "-o", str(image), FIRMWARE, check_code=0)
    assert "valid" in run("verify", "-p", str(public), str(image), check_code=0).stdout


def test_keys_of_another_curve_are_refused(tmp_path):
    key = tmp_path / "p384.pem"
    subprocess.run(["openssl", "ecparam", "-name", "secp384r1", "-genkey", "-noout", "-out", str(key)], check=True,
                   capture_output=True, timeout=60)
    refused = run("sign", "-k", str(key), "--board", "isa486", "--version", "1.0.0", "-o", str(tmp_path / "x"),
                  FIRMWARE, check_code=4)
    assert "P-256" in refused.stderr
    assert not (tmp_path / "x").exists()


def test_verify_accepts_the_image_and_says_why_it_refuses_a_bad_one(workspace):
    tmp_path, _, public, image = workspace
    out = json.loads(run("--json", "verify", "-p", str(public), str(image), check_code=0).stdout)
    assert out["valid"] is True and out["version"] == "1.2.3+7"
    data = image.read_bytes()
    cases = {
        "header bit": (lambda b: b[:30] + bytes([b[30] ^ 4]) + b[31:], "signature does not verify"),
        "payload bit": (lambda b: b[:5000] + bytes([b[5000] ^ 1]) + b[5001:], "payload is not the one"),
        "truncated": (lambda b: b[:-1], "truncated"),
        "extended": (lambda b: b + b"\0", "longer than its header says"),
        "not an image": (lambda b: b"\x7fELF" + b[4:], "not a DCOS controller image"),
        "unsigned": (lambda b: b[:SIGNED_SIZE] + bytes(64) + b[HEADER_SIZE:], "signature does not verify"),
    }
    for name, (change, reason) in cases.items():
        bad = tmp_path / "bad.dcos"
        bad.write_bytes(change(data))
        refused = run("verify", "-p", str(public), str(bad), check_code=1)
        assert reason in refused.stderr, f"{name}: {refused.stderr}"
        as_json = json.loads(run("--json", "verify", "-p", str(public), str(bad), check_code=1).stdout)
        assert as_json["valid"] is False and reason in as_json["reason"], name


def test_verify_refuses_another_key_and_a_downgrade_unless_allowed(workspace):
    tmp_path, _, public, image = workspace
    other = tmp_path / "other.pem"
    run("keygen", "-o", str(other), check_code=0)
    assert "does not trust" in run("verify", "-p", f"{other}.pub", str(image), check_code=1).stderr
    run("verify", "-p", f"{other}.pub", "-p", str(public), str(image), check_code=0)
    assert "older than the installed" in run("verify", "-p", str(public), "--installed", "1.2.4",
                                             str(image), check_code=1).stderr
    run("verify", "-p", str(public), "--installed", "1.2.4", "--allow-downgrade", str(image), check_code=0)
    run("verify", "-p", str(public), "--installed", "1.2.3+7", str(image), check_code=0)
    assert run("verify", "-p", str(public), "--installed", "1.2", str(image), check_code=2).returncode == 2


def test_sign_refuses_what_is_not_firmware_and_bad_arguments(workspace):
    tmp_path, key, _, image = workspace
    out = tmp_path / "out.dcos"
    assert "not an ELF file" in run("sign", "-k", str(key), "--board", "isa486", "--version", "1.0.0",
                                    "-o", str(out), str(image), check_code=1).stderr
    assert "unknown board" in run("sign", "-k", str(key), "--board", "p5", "--version", "1.0.0",
                                  "-o", str(out), FIRMWARE, check_code=2).stderr
    assert "MAJOR.MINOR.PATCH" in run("sign", "-k", str(key), "--board", "isa486", "--version", "1.0",
                                      "-o", str(out), FIRMWARE, check_code=2).stderr
    assert "cannot read" in run("sign", "-k", str(tmp_path / "none.pem"), "--board", "isa486", "--version",
                                "1.0.0", "-o", str(out), FIRMWARE, check_code=3).stderr
    assert not out.exists(), "a refused sign writes nothing"


def test_the_controller_verifies_images_with_mbedtls_built_for_the_i486(boot, isa486):
    # The test image links firmware/image with mbedTLS compiled from Debian's
    # source for the i486 (mk/mbedtls.mk; the i486 check covers it). It
    # verifies a real signed image and refuses it with one bit changed in the
    # header, the payload or the signature.
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    emulator.send("test image --exit\r")
    emulator.expect(r"the signed image: a valid image")
    emulator.expect(r"one header bit changed: the signature does not verify")
    emulator.expect(r"one payload bit changed: the payload is not the one its signed header describes")
    emulator.expect(r"one signature bit changed: the signature does not verify")
    emulator.expect_exit(EXIT_PASS)


def test_the_controllers_own_mbedtls_passes_wycheproof(boot, isa486):
    # The i486 build of mbedTLS has a configuration of its own
    # (firmware/image/mbedtls/dcos_mbedtls_config.h): it is checked against
    # all 219 Wycheproof P-256 SHA-256 cases on the emulated controller.
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    emulator.send("test wycheproof --exit\r")
    emulator.expect(r"219 vectors: 146 valid accepted, 69 invalid refused, 4 acceptable, 0 wrong", timeout=300)
    emulator.expect_exit(EXIT_PASS)
