//! Parameter ids (RTPS 2.5 table 9.18, the inline-QoS PIDs of table 9.17, and the DDS-XTypes,
//! DDS-RPC and DDS-Security additions robowire meets). Values checked against RTPS 2.5 §9.6.2 and
//! CycloneDDS `src/core/ddsi/src/ddsi__protocol.h`.

/// Bit 14: a receiver that does not know the PID must drop the whole list.
pub const MUST_UNDERSTAND: u16 = 0x4000;
/// Bit 15: the PID's meaning is the sender's vendor's.
pub const VENDOR_SPECIFIC: u16 = 0x8000;
/// PID_PAD: padding, skipped.
pub const PAD: u16 = 0x0000;
/// PID_SENTINEL: the end of a list.
pub const SENTINEL: u16 = 0x0001;
/// PID_PARTICIPANT_LEASE_DURATION: how long a participant lives without news (`Duration_t`).
pub const PARTICIPANT_LEASE_DURATION: u16 = 0x0002;
/// PID_PERSISTENCE: deprecated.
pub const PERSISTENCE: u16 = 0x0003;
/// PID_TIME_BASED_FILTER: TIME_BASED_FILTER QoS.
pub const TIME_BASED_FILTER: u16 = 0x0004;
/// PID_TOPIC_NAME: the topic's name (string).
pub const TOPIC_NAME: u16 = 0x0005;
/// PID_OWNERSHIP_STRENGTH: OWNERSHIP_STRENGTH QoS.
pub const OWNERSHIP_STRENGTH: u16 = 0x0006;
/// PID_TYPE_NAME: the type's name (string).
pub const TYPE_NAME: u16 = 0x0007;
/// PID_TYPE_CHECKSUM: deprecated.
pub const TYPE_CHECKSUM: u16 = 0x0008;
/// PID_TYPE2_NAME: deprecated.
pub const TYPE2_NAME: u16 = 0x0009;
/// PID_TYPE2_CHECKSUM: deprecated.
pub const TYPE2_CHECKSUM: u16 = 0x000a;
/// PID_METATRAFFIC_MULTICAST_IPADDRESS: deprecated (RTPS 2.0 and before).
pub const METATRAFFIC_MULTICAST_IPADDRESS: u16 = 0x000b;
/// PID_DEFAULT_UNICAST_IPADDRESS: deprecated (RTPS 2.0 and before).
pub const DEFAULT_UNICAST_IPADDRESS: u16 = 0x000c;
/// PID_METATRAFFIC_UNICAST_PORT: deprecated (RTPS 2.0 and before).
pub const METATRAFFIC_UNICAST_PORT: u16 = 0x000d;
/// PID_DEFAULT_UNICAST_PORT: deprecated (RTPS 2.0 and before).
pub const DEFAULT_UNICAST_PORT: u16 = 0x000e;
/// PID_DOMAIN_ID: the participant's domain id.
pub const DOMAIN_ID: u16 = 0x000f;
/// PID_EXPECTS_ACK: deprecated.
pub const EXPECTS_ACK: u16 = 0x0010;
/// PID_MULTICAST_IPADDRESS: deprecated (RTPS 2.0 and before).
pub const MULTICAST_IPADDRESS: u16 = 0x0011;
/// PID_MANAGER_KEY: deprecated.
pub const MANAGER_KEY: u16 = 0x0012;
/// PID_SEND_QUEUE_SIZE: deprecated.
pub const SEND_QUEUE_SIZE: u16 = 0x0013;
/// PID_RELIABILITY_ENABLED: deprecated.
pub const RELIABILITY_ENABLED: u16 = 0x0014;
/// PID_PROTOCOL_VERSION: the participant's RTPS version.
pub const PROTOCOL_VERSION: u16 = 0x0015;
/// PID_VENDORID: the participant's vendor id.
pub const VENDORID: u16 = 0x0016;
/// PID_VARGAPPS_SEQUENCE_NUMBER_LAST: deprecated.
pub const VARGAPPS_SEQUENCE_NUMBER_LAST: u16 = 0x0017;
/// PID_RECV_QUEUE_SIZE: deprecated.
pub const RECV_QUEUE_SIZE: u16 = 0x0018;
/// PID_RELIABILITY_OFFERED: deprecated.
pub const RELIABILITY_OFFERED: u16 = 0x0019;
/// PID_RELIABILITY: RELIABILITY QoS.
pub const RELIABILITY: u16 = 0x001a;
/// PID_LIVELINESS: LIVELINESS QoS.
pub const LIVELINESS: u16 = 0x001b;
/// PID_DURABILITY: DURABILITY QoS.
pub const DURABILITY: u16 = 0x001d;
/// PID_DURABILITY_SERVICE: DURABILITY_SERVICE QoS.
pub const DURABILITY_SERVICE: u16 = 0x001e;
/// PID_OWNERSHIP: OWNERSHIP QoS.
pub const OWNERSHIP: u16 = 0x001f;
/// PID_PRESENTATION: PRESENTATION QoS.
pub const PRESENTATION: u16 = 0x0021;
/// PID_DEADLINE: DEADLINE QoS.
pub const DEADLINE: u16 = 0x0023;
/// PID_DESTINATION_ORDER: DESTINATION_ORDER QoS.
pub const DESTINATION_ORDER: u16 = 0x0025;
/// PID_LATENCY_BUDGET: LATENCY_BUDGET QoS.
pub const LATENCY_BUDGET: u16 = 0x0027;
/// PID_PARTITION: PARTITION QoS (a sequence of strings).
pub const PARTITION: u16 = 0x0029;
/// PID_LIFESPAN: LIFESPAN QoS.
pub const LIFESPAN: u16 = 0x002b;
/// PID_USER_DATA: USER_DATA QoS (octets).
pub const USER_DATA: u16 = 0x002c;
/// PID_GROUP_DATA: GROUP_DATA QoS (octets).
pub const GROUP_DATA: u16 = 0x002d;
/// PID_TOPIC_DATA: TOPIC_DATA QoS (octets).
pub const TOPIC_DATA: u16 = 0x002e;
/// PID_UNICAST_LOCATOR: an endpoint's unicast locator.
pub const UNICAST_LOCATOR: u16 = 0x002f;
/// PID_MULTICAST_LOCATOR: an endpoint's multicast locator.
pub const MULTICAST_LOCATOR: u16 = 0x0030;
/// PID_DEFAULT_UNICAST_LOCATOR: a participant's default unicast locator (user traffic).
pub const DEFAULT_UNICAST_LOCATOR: u16 = 0x0031;
/// PID_METATRAFFIC_UNICAST_LOCATOR: a participant's unicast locator for discovery traffic.
pub const METATRAFFIC_UNICAST_LOCATOR: u16 = 0x0032;
/// PID_METATRAFFIC_MULTICAST_LOCATOR: a participant's multicast locator for discovery traffic.
pub const METATRAFFIC_MULTICAST_LOCATOR: u16 = 0x0033;
/// PID_PARTICIPANT_MANUAL_LIVELINESS_COUNT: the participant's manual liveliness count.
pub const PARTICIPANT_MANUAL_LIVELINESS_COUNT: u16 = 0x0034;
/// PID_CONTENT_FILTER_PROPERTY: a content-filtered topic's filter.
pub const CONTENT_FILTER_PROPERTY: u16 = 0x0035;
/// PID_HISTORY: HISTORY QoS.
pub const HISTORY: u16 = 0x0040;
/// PID_RESOURCE_LIMITS: RESOURCE_LIMITS QoS.
pub const RESOURCE_LIMITS: u16 = 0x0041;
/// PID_EXPECTS_INLINE_QOS: the reader wants inline QoS with every DATA.
pub const EXPECTS_INLINE_QOS: u16 = 0x0043;
/// PID_PARTICIPANT_BUILTIN_ENDPOINTS: deprecated form of PID_BUILTIN_ENDPOINT_SET.
pub const PARTICIPANT_BUILTIN_ENDPOINTS: u16 = 0x0044;
/// PID_METATRAFFIC_UNICAST_IPADDRESS: deprecated (RTPS 2.0 and before).
pub const METATRAFFIC_UNICAST_IPADDRESS: u16 = 0x0045;
/// PID_METATRAFFIC_MULTICAST_PORT: deprecated (RTPS 2.0 and before).
pub const METATRAFFIC_MULTICAST_PORT: u16 = 0x0046;
/// PID_DEFAULT_MULTICAST_LOCATOR: a participant's default multicast locator (user traffic).
pub const DEFAULT_MULTICAST_LOCATOR: u16 = 0x0048;
/// PID_TRANSPORT_PRIORITY: TRANSPORT_PRIORITY QoS.
pub const TRANSPORT_PRIORITY: u16 = 0x0049;
/// PID_PARTICIPANT_GUID: the participant's GUID.
pub const PARTICIPANT_GUID: u16 = 0x0050;
/// PID_PARTICIPANT_ENTITYID: deprecated.
pub const PARTICIPANT_ENTITYID: u16 = 0x0051;
/// PID_GROUP_GUID: the publisher's or subscriber's GUID.
pub const GROUP_GUID: u16 = 0x0052;
/// PID_GROUP_ENTITYID: deprecated.
pub const GROUP_ENTITYID: u16 = 0x0053;
/// PID_CONTENT_FILTER_INFO: inline QoS: which filters a sample passed.
pub const CONTENT_FILTER_INFO: u16 = 0x0055;
/// PID_COHERENT_SET: inline QoS: the coherent set a sample belongs to.
pub const COHERENT_SET: u16 = 0x0056;
/// PID_DIRECTED_WRITE: inline QoS: the readers a sample is for.
pub const DIRECTED_WRITE: u16 = 0x0057;
/// PID_BUILTIN_ENDPOINT_SET: the participant's builtin endpoints (a bit set).
pub const BUILTIN_ENDPOINT_SET: u16 = 0x0058;
/// PID_PROPERTY_LIST: name/value properties.
pub const PROPERTY_LIST: u16 = 0x0059;
/// PID_ENDPOINT_GUID: the endpoint's GUID.
pub const ENDPOINT_GUID: u16 = 0x005a;
/// PID_TYPE_MAX_SIZE_SERIALIZED: the largest serialized size of the type.
pub const TYPE_MAX_SIZE_SERIALIZED: u16 = 0x0060;
/// PID_ORIGINAL_WRITER_INFO: inline QoS: the writer a relayed sample came from.
pub const ORIGINAL_WRITER_INFO: u16 = 0x0061;
/// PID_ENTITY_NAME: ENTITY_NAME QoS (string).
pub const ENTITY_NAME: u16 = 0x0062;
/// PID_GROUP_COHERENT_SET: inline QoS: the group coherent set a sample belongs to.
pub const GROUP_COHERENT_SET: u16 = 0x0063;
/// PID_GROUP_SEQ_NUM: inline QoS: the sample's number in its group.
pub const GROUP_SEQ_NUM: u16 = 0x0064;
/// PID_WRITER_GROUP_INFO: inline QoS: the writers of a group coherent set.
pub const WRITER_GROUP_INFO: u16 = 0x0065;
/// PID_SECURE_WRITER_GROUP_INFO: inline QoS: the secure writers of a group coherent set.
pub const SECURE_WRITER_GROUP_INFO: u16 = 0x0066;
/// PID_KEY_HASH: inline QoS: the sample's key hash (16 bytes).
pub const KEY_HASH: u16 = 0x0070;
/// PID_STATUS_INFO: inline QoS: disposed / unregistered / filtered flags (4 bytes, big-endian).
pub const STATUS_INFO: u16 = 0x0071;
/// PID_DATA_REPRESENTATION: DATA_REPRESENTATION QoS (DDS-XTypes).
pub const DATA_REPRESENTATION: u16 = 0x0073;
/// PID_TYPE_CONSISTENCY_ENFORCEMENT: TYPE_CONSISTENCY_ENFORCEMENT QoS (DDS-XTypes).
pub const TYPE_CONSISTENCY_ENFORCEMENT: u16 = 0x0074;
/// PID_TYPE_INFORMATION: the type's TypeInformation (DDS-XTypes).
pub const TYPE_INFORMATION: u16 = 0x0075;
/// PID_BUILTIN_ENDPOINT_QOS: QoS of the builtin endpoints (BEST_EFFORT_PARTICIPANT_MESSAGE_DATA_READER).
pub const BUILTIN_ENDPOINT_QOS: u16 = 0x0077;
/// PID_RELATED_SAMPLE_IDENTITY: inline QoS: the request a reply answers (DDS-RPC).
pub const RELATED_SAMPLE_IDENTITY: u16 = 0x0083;
/// PID_IDENTITY_TOKEN: DDS-Security: the participant's identity token.
pub const IDENTITY_TOKEN: u16 = 0x1001;
/// PID_PERMISSIONS_TOKEN: DDS-Security: the participant's permissions token.
pub const PERMISSIONS_TOKEN: u16 = 0x1002;
/// PID_DATA_TAGS: DDS-Security: data tags.
pub const DATA_TAGS: u16 = 0x1003;
/// PID_ENDPOINT_SECURITY_INFO: DDS-Security: the endpoint's security attributes.
pub const ENDPOINT_SECURITY_INFO: u16 = 0x1004;
/// PID_PARTICIPANT_SECURITY_INFO: DDS-Security: the participant's security attributes.
pub const PARTICIPANT_SECURITY_INFO: u16 = 0x1005;
/// PID_IDENTITY_STATUS_TOKEN: DDS-Security: identity status token.
pub const IDENTITY_STATUS_TOKEN: u16 = 0x1006;
/// PID_DOMAIN_TAG: the participant's domain tag (string; must be understood).
pub const DOMAIN_TAG: u16 = 0x4014;
/// Inline QoS: PID_RELATED_SAMPLE_IDENTITY at its pre-standard vendor-specific id (RTI Connext, Fast DDS).
pub const RELATED_SAMPLE_IDENTITY_LEGACY: u16 = 0x800f;

/// The PID's name ("PID_TOPIC_NAME"), the must-understand bit ignored for standard PIDs;
/// `None` for unknown PIDs and for vendor-specific ones (bit 15) whose meaning depends on the
/// vendor (only 0x800f, the legacy PID_RELATED_SAMPLE_IDENTITY, is named).
pub fn name(pid: u16) -> Option<&'static str> {
    if pid & VENDOR_SPECIFIC != 0 {
        return (pid == RELATED_SAMPLE_IDENTITY_LEGACY).then_some("PID_RELATED_SAMPLE_IDENTITY");
    }
    standard_name(pid).or_else(|| standard_name(pid & !MUST_UNDERSTAND))
}

fn standard_name(pid: u16) -> Option<&'static str> {
    Some(match pid {
        PAD => "PID_PAD",
        SENTINEL => "PID_SENTINEL",
        PARTICIPANT_LEASE_DURATION => "PID_PARTICIPANT_LEASE_DURATION",
        PERSISTENCE => "PID_PERSISTENCE",
        TIME_BASED_FILTER => "PID_TIME_BASED_FILTER",
        TOPIC_NAME => "PID_TOPIC_NAME",
        OWNERSHIP_STRENGTH => "PID_OWNERSHIP_STRENGTH",
        TYPE_NAME => "PID_TYPE_NAME",
        TYPE_CHECKSUM => "PID_TYPE_CHECKSUM",
        TYPE2_NAME => "PID_TYPE2_NAME",
        TYPE2_CHECKSUM => "PID_TYPE2_CHECKSUM",
        METATRAFFIC_MULTICAST_IPADDRESS => "PID_METATRAFFIC_MULTICAST_IPADDRESS",
        DEFAULT_UNICAST_IPADDRESS => "PID_DEFAULT_UNICAST_IPADDRESS",
        METATRAFFIC_UNICAST_PORT => "PID_METATRAFFIC_UNICAST_PORT",
        DEFAULT_UNICAST_PORT => "PID_DEFAULT_UNICAST_PORT",
        DOMAIN_ID => "PID_DOMAIN_ID",
        EXPECTS_ACK => "PID_EXPECTS_ACK",
        MULTICAST_IPADDRESS => "PID_MULTICAST_IPADDRESS",
        MANAGER_KEY => "PID_MANAGER_KEY",
        SEND_QUEUE_SIZE => "PID_SEND_QUEUE_SIZE",
        RELIABILITY_ENABLED => "PID_RELIABILITY_ENABLED",
        PROTOCOL_VERSION => "PID_PROTOCOL_VERSION",
        VENDORID => "PID_VENDORID",
        VARGAPPS_SEQUENCE_NUMBER_LAST => "PID_VARGAPPS_SEQUENCE_NUMBER_LAST",
        RECV_QUEUE_SIZE => "PID_RECV_QUEUE_SIZE",
        RELIABILITY_OFFERED => "PID_RELIABILITY_OFFERED",
        RELIABILITY => "PID_RELIABILITY",
        LIVELINESS => "PID_LIVELINESS",
        DURABILITY => "PID_DURABILITY",
        DURABILITY_SERVICE => "PID_DURABILITY_SERVICE",
        OWNERSHIP => "PID_OWNERSHIP",
        PRESENTATION => "PID_PRESENTATION",
        DEADLINE => "PID_DEADLINE",
        DESTINATION_ORDER => "PID_DESTINATION_ORDER",
        LATENCY_BUDGET => "PID_LATENCY_BUDGET",
        PARTITION => "PID_PARTITION",
        LIFESPAN => "PID_LIFESPAN",
        USER_DATA => "PID_USER_DATA",
        GROUP_DATA => "PID_GROUP_DATA",
        TOPIC_DATA => "PID_TOPIC_DATA",
        UNICAST_LOCATOR => "PID_UNICAST_LOCATOR",
        MULTICAST_LOCATOR => "PID_MULTICAST_LOCATOR",
        DEFAULT_UNICAST_LOCATOR => "PID_DEFAULT_UNICAST_LOCATOR",
        METATRAFFIC_UNICAST_LOCATOR => "PID_METATRAFFIC_UNICAST_LOCATOR",
        METATRAFFIC_MULTICAST_LOCATOR => "PID_METATRAFFIC_MULTICAST_LOCATOR",
        PARTICIPANT_MANUAL_LIVELINESS_COUNT => "PID_PARTICIPANT_MANUAL_LIVELINESS_COUNT",
        CONTENT_FILTER_PROPERTY => "PID_CONTENT_FILTER_PROPERTY",
        HISTORY => "PID_HISTORY",
        RESOURCE_LIMITS => "PID_RESOURCE_LIMITS",
        EXPECTS_INLINE_QOS => "PID_EXPECTS_INLINE_QOS",
        PARTICIPANT_BUILTIN_ENDPOINTS => "PID_PARTICIPANT_BUILTIN_ENDPOINTS",
        METATRAFFIC_UNICAST_IPADDRESS => "PID_METATRAFFIC_UNICAST_IPADDRESS",
        METATRAFFIC_MULTICAST_PORT => "PID_METATRAFFIC_MULTICAST_PORT",
        DEFAULT_MULTICAST_LOCATOR => "PID_DEFAULT_MULTICAST_LOCATOR",
        TRANSPORT_PRIORITY => "PID_TRANSPORT_PRIORITY",
        PARTICIPANT_GUID => "PID_PARTICIPANT_GUID",
        PARTICIPANT_ENTITYID => "PID_PARTICIPANT_ENTITYID",
        GROUP_GUID => "PID_GROUP_GUID",
        GROUP_ENTITYID => "PID_GROUP_ENTITYID",
        CONTENT_FILTER_INFO => "PID_CONTENT_FILTER_INFO",
        COHERENT_SET => "PID_COHERENT_SET",
        DIRECTED_WRITE => "PID_DIRECTED_WRITE",
        BUILTIN_ENDPOINT_SET => "PID_BUILTIN_ENDPOINT_SET",
        PROPERTY_LIST => "PID_PROPERTY_LIST",
        ENDPOINT_GUID => "PID_ENDPOINT_GUID",
        TYPE_MAX_SIZE_SERIALIZED => "PID_TYPE_MAX_SIZE_SERIALIZED",
        ORIGINAL_WRITER_INFO => "PID_ORIGINAL_WRITER_INFO",
        ENTITY_NAME => "PID_ENTITY_NAME",
        GROUP_COHERENT_SET => "PID_GROUP_COHERENT_SET",
        GROUP_SEQ_NUM => "PID_GROUP_SEQ_NUM",
        WRITER_GROUP_INFO => "PID_WRITER_GROUP_INFO",
        SECURE_WRITER_GROUP_INFO => "PID_SECURE_WRITER_GROUP_INFO",
        KEY_HASH => "PID_KEY_HASH",
        STATUS_INFO => "PID_STATUS_INFO",
        DATA_REPRESENTATION => "PID_DATA_REPRESENTATION",
        TYPE_CONSISTENCY_ENFORCEMENT => "PID_TYPE_CONSISTENCY_ENFORCEMENT",
        TYPE_INFORMATION => "PID_TYPE_INFORMATION",
        BUILTIN_ENDPOINT_QOS => "PID_BUILTIN_ENDPOINT_QOS",
        RELATED_SAMPLE_IDENTITY => "PID_RELATED_SAMPLE_IDENTITY",
        IDENTITY_TOKEN => "PID_IDENTITY_TOKEN",
        PERMISSIONS_TOKEN => "PID_PERMISSIONS_TOKEN",
        DATA_TAGS => "PID_DATA_TAGS",
        ENDPOINT_SECURITY_INFO => "PID_ENDPOINT_SECURITY_INFO",
        PARTICIPANT_SECURITY_INFO => "PID_PARTICIPANT_SECURITY_INFO",
        IDENTITY_STATUS_TOKEN => "PID_IDENTITY_STATUS_TOKEN",
        DOMAIN_TAG => "PID_DOMAIN_TAG",
        _ => return None,
    })
}
