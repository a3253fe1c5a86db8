"""The rig's address space table, the endpoint rule and the security settings, without a
server (issue 33)."""

from __future__ import annotations

import asyncio

import pytest
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from cryptography.x509.oid import ExtendedKeyUsageOID

from drill_sim_ros.hil.address_space import (
    VARIABLES,
    markdown_table,
    node_id,
    rig_name,
    unece_unit_id,
)
from drill_sim_ros.hil.endpoint import check_endpoint, is_loopback
from drill_sim_ros.hil.security import APPLICATION_URI, PasswordUser, load_security
from drill_sim_ros.model.errors import ParameterError

ISSUE_33_NAMES = {"DriveSpeed", "MotorTorque", "QuillTorque", "HookLoad", "WobEstimate",
                  "BitDepth", "Rop", "SimTime", "SpeedSetpoint", "TorqueCommand",
                  "WobSetpoint", "DriveMode", "CommandCounter", "SampleCounter", "Lockstep",
                  "Status", "RejectedWrites"}
ISSUE_53_NAMES = {"Heartbeat", "StatusText", "ControlPeriod"}


def test_the_variables_are_the_issues_browse_names_and_the_table_lists_them() -> None:
    assert {v.name for v in VARIABLES} == ISSUE_33_NAMES | ISSUE_53_NAMES
    table = markdown_table()
    for name in ISSUE_33_NAMES | ISSUE_53_NAMES | {"Step()", "Reset()"}:
        assert f"| `{name}` |" in table
    assert {v.name for v in VARIABLES if v.writable} == {
        "SpeedSetpoint", "TorqueCommand", "WobSetpoint", "DriveMode", "CommandCounter",
        "Heartbeat"}


def test_unece_unit_ids_follow_opc_ua_part_8() -> None:
    # the published ids of the common codes: metre 5067858, newton 5129559, rad/s 12865
    assert unece_unit_id("MTR") == 5067858
    assert unece_unit_id("NEW") == 5129559
    assert unece_unit_id("2A") == 12865


def test_rig_names_and_node_ids() -> None:
    assert rig_name("/") == rig_name("") == "Rig"
    assert rig_name("/site/rig2") == "rig2"
    assert node_id("Rig", "DriveSpeed") == "Rig.DriveSpeed"


@pytest.mark.parametrize("endpoint", ["opc.tcp://127.0.0.1:4840/drill_sim/",
                                      "opc.tcp://localhost:4841/", "opc.tcp://[::1]:4840/"])
def test_loopback_endpoints_pass(endpoint: str) -> None:
    check_endpoint(endpoint)


@pytest.mark.parametrize(("endpoint", "says"), [
    ("opc.tcp://0.0.0.0:4840/", "off loopback"), ("opc.tcp://10.1.2.3:4840/", "off loopback"),
    ("opc.tcp://plc.example.org:4840/", "off loopback"),
    ("opc.tcp://127.0.0.1/", "not opc.tcp://HOST:PORT/PATH"),
    ("tcp://127.0.0.1:4840/", "not opc.tcp://HOST:PORT/PATH")])
def test_other_endpoints_are_refused_in_one_line(endpoint: str, says: str) -> None:
    with pytest.raises(ParameterError, match=says) as refused:
        check_endpoint(endpoint)
    assert "\n" not in str(refused.value)
    assert not is_loopback("0.0.0.0")


def test_a_secured_gateway_may_bind_off_loopback() -> None:
    check_endpoint("opc.tcp://0.0.0.0:4840/drill_sim/", secured=True)


def make_certificate(folder, name: str, uri: str) -> tuple[str, str]:
    """A self-signed server certificate (DER) with ``uri``, and its key (PEM)."""
    cert, key = folder / f"{name}_cert.der", folder / f"{name}_key.pem"
    asyncio.run(setup_self_signed_certificate(key, cert, uri, "localhost",
                                              [ExtendedKeyUsageOID.SERVER_AUTH], {}))
    return str(cert), str(key)


def test_security_settings_all_or_none(tmp_path) -> None:
    names = ("security.certificate", "security.private_key", "security.user",
             "security.password_file")
    assert load_security(dict.fromkeys(names, "")) is None
    with pytest.raises(ParameterError, match=r"missing: security\.private_key"):
        load_security({"security.certificate": "c.der", "security.user": "plc",
                       "security.password_file": "p"})
    cert, key = make_certificate(tmp_path, "server", APPLICATION_URI)
    password = tmp_path / "password"
    password.write_text("")
    values = {"security.certificate": cert, "security.private_key": key,
              "security.user": "plc", "security.password_file": str(password)}
    with pytest.raises(ParameterError, match="is empty"):
        load_security(values)
    password.write_text("s3cret\nignored\n")
    security = load_security(values)
    assert (security.user, security.password) == ("plc", "s3cret")
    users = PasswordUser("plc", "s3cret")
    assert users.get_user(None, "plc", "s3cret") is not None
    assert users.get_user(None, "plc", "guess") is None
    assert users.get_user(None, "other", "s3cret") is None
    assert users.get_user(None) is None


def test_a_certificate_of_another_uri_or_another_key_is_refused_in_one_line(tmp_path) -> None:
    cert, key = make_certificate(tmp_path, "server", APPLICATION_URI)
    other_cert, other_key = make_certificate(tmp_path, "other", "urn:somebody:else")
    (tmp_path / "password").write_text("s3cret\n")
    values = {"security.certificate": cert, "security.private_key": key,
              "security.user": "plc", "security.password_file": str(tmp_path / "password")}
    for changes, says in (({"security.certificate": other_cert,
                            "security.private_key": other_key}, "is for urn:somebody:else"),
                          ({"security.private_key": other_key}, "is not the key of"),
                          ({"security.private_key": str(tmp_path / "password")},
                           "not an unencrypted PEM private key"),
                          ({"security.certificate": str(tmp_path / "password")},
                           "not a DER or PEM certificate")):
        with pytest.raises(ParameterError, match=says) as refused:
            load_security(values | changes)
        assert "\n" not in str(refused.value)
