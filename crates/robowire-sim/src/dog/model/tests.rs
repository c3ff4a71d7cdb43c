use super::*;

/// `seconds` of a client streaming the latched command every 2 ms.
fn run_for(dog: &mut DogModel, seconds: f32) {
    for _ in 0..(seconds / 0.002) as usize {
        let (command, model) = (dog.command, dog.model);
        dog.on_high_level(&command, model);
        dog.step(0.002);
    }
}

/// `seconds` without any command.
fn run_silent(dog: &mut DogModel, seconds: f32) {
    for _ in 0..(seconds / 0.002) as usize {
        dog.step(0.002);
    }
}

#[test]
fn stands_up_in_time_walks_and_lies_down() {
    let mut dog = DogModel::new(Model::Zsl1);
    assert!(dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1));
    assert_eq!(dog.mode(), ControlMode::Stand, "the mode mirrors the command at once");
    run_for(&mut dog, STAND_UP_S / 2.0);
    assert_eq!(dog.activity(), Activity::StandingUp);
    run_for(&mut dog, STAND_UP_S / 2.0 + 0.3);
    assert_eq!(dog.activity(), Activity::Standing);
    assert!((dog.position_m()[2] - super::super::STANDING_HEIGHT_M).abs() < 0.01);

    dog.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
    run_for(&mut dog, 2.0);
    let x = dog.position_m()[0];
    assert!((0.8..1.0).contains(&x), "about 2 s at 0.5 m/s minus the lag: {x}");
    dog.on_high_level(&HighLevelCommand::move_velocity(0.0, 0.0, 0.0), Model::Zsl1);
    run_for(&mut dog, 1.0);
    assert!(dog.velocity_mps()[0].abs() < 0.01);

    dog.on_high_level(&HighLevelCommand::lie_down(), Model::Zsl1);
    run_for(&mut dog, LIE_DOWN_S + 0.1);
    assert_eq!(dog.activity(), Activity::Lying);
    assert!(dog.battery_percent() < 100.0);
}

#[test]
fn a_trick_returns_to_stand_and_the_other_models_magic_raises_the_mismatch_flag() {
    let mut dog = DogModel::new(Model::Zsl1);
    dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
    run_for(&mut dog, STAND_UP_S + 0.1);
    dog.on_high_level(&HighLevelCommand::jump(), Model::Zsl1);
    assert_eq!(dog.activity(), Activity::Trick(Action::Jump));
    run_for(&mut dog, JUMP_S + 0.2);
    assert_eq!((dog.activity(), dog.tricks_done()), (Activity::Standing, 1));
    assert_eq!(dog.high_level_state().sdk_mismatch.get(), 0);
    dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1W);
    assert_eq!(dog.high_level_state().sdk_mismatch.get(), 1);
}

#[test]
fn the_idle_stream_is_no_request_and_a_silent_client_stops_the_walk() {
    let mut dog = DogModel::new(Model::Zsl1);
    assert!(!dog.on_high_level(&HighLevelCommand::default(), Model::Zsl1));
    assert_eq!(dog.mode(), ControlMode::LieDown);
    dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
    run_for(&mut dog, STAND_UP_S + 0.1);
    dog.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
    run_for(&mut dog, 0.4);
    assert!(dog.velocity_mps()[0] > 0.4);
    run_silent(&mut dog, COMMAND_TIMEOUT_S + 0.5);
    assert!(dog.velocity_mps()[0] < 0.05, "no command for the timeout: the dog stops");
    assert_eq!(dog.mode(), ControlMode::Move);
}

#[test]
fn low_level_pd_moves_the_joints() {
    let mut dog = DogModel::new(Model::Zsl1);
    let stand = LowLevelCommand::new(zsl_proto::udp::MotorCommand::pd_hold(
        [[0.0; 4], [0.8; 4], [-1.5; 4]],
        [80.0; 3],
        [1.0; 3],
    ));
    for _ in 0..500 {
        dog.on_low_level(&stand);
        dog.step(0.002);
    }
    let state = dog.low_level_state();
    assert!((state.motor.q[2][0].get() + 1.5).abs() < 0.01, "{:?}", state.motor.q);
    assert_eq!(dog.activity(), Activity::LowLevel);
    run_silent(&mut dog, 0.2);
    assert_eq!(dog.activity(), Activity::Passive, "motors released when LowLevel commands stop");
}
