use super::*;

/// `seconds` of a client streaming the latched command every 2 ms.
fn run_for(robot: &mut Zsl1Model, seconds: f32) {
    for _ in 0..(seconds / 0.002) as usize {
        let (command, model) = (robot.command, robot.model);
        robot.on_high_level(&command, model);
        robot.step(0.002);
    }
}

/// `seconds` without any command.
fn run_silent(robot: &mut Zsl1Model, seconds: f32) {
    for _ in 0..(seconds / 0.002) as usize {
        robot.step(0.002);
    }
}

#[test]
fn stands_up_in_time_walks_and_lies_down() {
    let mut robot = Zsl1Model::new(Model::Zsl1);
    assert!(robot.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1));
    assert_eq!(robot.mode(), ControlMode::Stand, "the mode mirrors the command at once");
    run_for(&mut robot, STAND_UP_S / 2.0);
    assert_eq!(robot.activity(), Activity::StandingUp);
    run_for(&mut robot, STAND_UP_S / 2.0 + 0.3);
    assert_eq!(robot.activity(), Activity::Standing);
    assert!((robot.position_m()[2] - super::super::STANDING_HEIGHT_M).abs() < 0.01);

    robot.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
    run_for(&mut robot, 2.0);
    let x = robot.position_m()[0];
    assert!((0.8..1.0).contains(&x), "about 2 s at 0.5 m/s minus the lag: {x}");
    robot.on_high_level(&HighLevelCommand::move_velocity(0.0, 0.0, 0.0), Model::Zsl1);
    run_for(&mut robot, 1.0);
    assert!(robot.velocity_mps()[0].abs() < 0.01);

    robot.on_high_level(&HighLevelCommand::lie_down(), Model::Zsl1);
    run_for(&mut robot, LIE_DOWN_S + 0.1);
    assert_eq!(robot.activity(), Activity::Lying);
    assert!(robot.battery_percent() < 100.0);
}

#[test]
fn a_trick_returns_to_stand_and_the_other_models_magic_raises_the_mismatch_flag() {
    let mut robot = Zsl1Model::new(Model::Zsl1);
    robot.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
    run_for(&mut robot, STAND_UP_S + 0.1);
    robot.on_high_level(&HighLevelCommand::jump(), Model::Zsl1);
    assert_eq!(robot.activity(), Activity::Trick(Action::Jump));
    run_for(&mut robot, JUMP_S + 0.2);
    assert_eq!((robot.activity(), robot.tricks_done()), (Activity::Standing, 1));
    assert_eq!(robot.high_level_state().sdk_mismatch.get(), 0);
    robot.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1W);
    assert_eq!(robot.high_level_state().sdk_mismatch.get(), 1);
}

#[test]
fn the_idle_stream_is_no_request_and_a_silent_client_stops_the_walk() {
    let mut robot = Zsl1Model::new(Model::Zsl1);
    assert!(!robot.on_high_level(&HighLevelCommand::default(), Model::Zsl1));
    assert_eq!(robot.mode(), ControlMode::LieDown);
    robot.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
    run_for(&mut robot, STAND_UP_S + 0.1);
    robot.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
    run_for(&mut robot, 0.4);
    assert!(robot.velocity_mps()[0] > 0.4);
    run_silent(&mut robot, COMMAND_TIMEOUT_S + 0.5);
    assert!(robot.velocity_mps()[0] < 0.05, "no command for the timeout: the robot stops");
    assert_eq!(robot.mode(), ControlMode::Move);
}

#[test]
fn low_level_pd_moves_the_joints() {
    let mut robot = Zsl1Model::new(Model::Zsl1);
    let stand = LowLevelCommand::new(zsl_proto::udp::MotorCommand::pd_hold(
        [[0.0; 4], [0.8; 4], [-1.5; 4]],
        [80.0; 3],
        [1.0; 3],
    ));
    for _ in 0..500 {
        robot.on_low_level(&stand);
        robot.step(0.002);
    }
    let state = robot.low_level_state();
    assert!((state.motor.q[2][0].get() + 1.5).abs() < 0.01, "{:?}", state.motor.q);
    assert_eq!(robot.activity(), Activity::LowLevel);
    run_silent(&mut robot, 0.2);
    assert_eq!(robot.activity(), Activity::Passive, "motors released when LowLevel commands stop");
}
