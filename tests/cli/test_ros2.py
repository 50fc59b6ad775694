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
