#include "format.hpp"

namespace dyad::mcap::format {

const char* OpcodeName(std::uint8_t op) {
  switch (op) {
    case kHeader: return "Header";
    case kFooter: return "Footer";
    case kSchema: return "Schema";
    case kChannel: return "Channel";
    case kMessage: return "Message";
    case kChunk: return "Chunk";
    case kMessageIndex: return "MessageIndex";
    case kChunkIndex: return "ChunkIndex";
    case kAttachment: return "Attachment";
    case kAttachmentIndex: return "AttachmentIndex";
    case kStatistics: return "Statistics";
    case kMetadata: return "Metadata";
    case kMetadataIndex: return "MetadataIndex";
    case kSummaryOffset: return "SummaryOffset";
    case kDataEnd: return "DataEnd";
    default: return "Unknown";
  }
}

}  // namespace dyad::mcap::format
