"""phantom-pin ros2 and sim-driver (cli/ros2.py): their refusals, before ROS starts, in one line
naming the option, exit 2."""

from helpers import installed_profiles

INSTALLED = installed_profiles()


def test_the_node_refuses_a_profile_whose_message_type_is_missing_and_bad_options_in_one_line(cli):
    """In process (the refusals come before ROS starts): one line naming the option, exit 2."""
    cases = [(["ros2", "--driver", "nosuch"], "--driver"),
             (["ros2", "--max-force", "-1", "--driver", "sawsensablephantom"], "--max-force"),
             (["ros2", "--max-force", "nan", "--driver", "sawsensablephantom"], "--max-force"),
             (["ros2", "--topic", "gravity_torque=tip_pose"], "--topic"),
             (["ros2", "--topic", "wrench=a", "--topic", "wrench=b"], "--topic"),
             (["ros2", "--compensate", "none"], "--compensate"),
             (["ros2", "--relay"], "--relay"),
             (["sim-driver", "--driver", "sawsensablephantom", "--theta0", "0", "9", "0"], "--theta0"),
             (["sim-driver", "--driver", "sawsensablephantom", "--hold", "-1"], "--hold"),
             (["sim-driver", "--driver", "sawsensablephantom", "--gimbal", "0", "5", "0"], "--gimbal"),
             (["sim-driver", "--driver", "sawsensablephantom", "--rate", "0"], "--rate")]
    if "geomagic_touch_ros2" not in INSTALLED:
        cases.append((["ros2", "--driver", "geomagic_touch_ros2"], "--driver"))
    for args, option in cases:
        code, _, err = cli("--model", "touch", *args)
        assert code == 2 and len(err.strip().splitlines()) == 1 and option in err, (args, err)
    code, _, err = cli("ros2", "--driver", "sawsensablephantom")     # premium_1_5: no stylus gimbal
    assert code == 2 and "--model touch" in err


def test_sim_driver_holds_the_stylus_at_its_gimbal_option(cli, monkeypatch):
    """sim-driver --gimbal G: the simulated device's arm carries the stylus at G, its gravity the
    report's closed form plus the gimbal links' potential gradient at G (references.gimbal, SymPy
    integrals of the stated geometry; 1e-9 N m), and the driver publishes G (spin is replaced: no
    ROS loop runs)."""
    import numpy as np

    from phantom_pin import closed_form, config
    from phantom_pin.interfaces.ros2 import simulated_driver
    from references.gimbal import gimbal_gravity

    ran = {}
    monkeypatch.setattr(simulated_driver, "spin", lambda simulation, angles, prefix: ran.update(
        simulation=simulation, angles=angles, prefix=prefix) or 0)
    gimbal = np.array([0.3, -0.4, 0.5])
    code, _, err = cli("--model", "touch", "sim-driver", "--driver", "sawsensablephantom", "--gimbal", *gimbal)
    assert code == 0, err
    np.testing.assert_array_equal(ran["angles"], gimbal)
    theta = np.array([0.2, 0.5, 0.7])
    expected = closed_form.gravity(theta, config.read("touch").report) + gimbal_gravity(theta, gimbal)
    np.testing.assert_allclose(ran["simulation"].device.phantom.gravity(theta), expected, rtol=0, atol=1e-9)
