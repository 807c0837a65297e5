// The firmware's EEPROM image in two flash banks (src/firmware/banked_nvm.h): a write cut short
// at any step, as a reset would, leaves the old image or the new one.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <vector>

#include "firmware/banked_nvm.h"

namespace motwin::firmware {
namespace {

constexpr size_t kPayload = 10;
using Nvm = BankedNvm<kPayload>;

void format_counting(uint8_t* image, size_t size) {
  for (size_t i = 0; i < size; ++i) image[i] = static_cast<uint8_t>(i);
}

std::vector<uint8_t> image_of(const Nvm& nvm) { return {nvm.data(), nvm.data() + nvm.size()}; }

TEST(FirmwareBankedNvm, Crc32IsZlibs) {
  const uint8_t text[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc32(text, sizeof text), 0xCBF43926u);
}

TEST(FirmwareBankedNvm, ErasedRegionGetsTheFactoryImageAndKeepsIt) {
  std::array<uint8_t, Nvm::kRegionSize> region;
  region.fill(Nvm::kErased);
  Nvm first(region.data());
  EXPECT_FALSE(first.open(format_counting));
  EXPECT_EQ(image_of(first), (std::vector<uint8_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));

  Nvm after_reset(region.data());
  EXPECT_TRUE(after_reset.open([](uint8_t*, size_t) { FAIL() << "a valid image is not formatted again"; }));
  EXPECT_EQ(image_of(after_reset), image_of(first));
}

TEST(FirmwareBankedNvm, WritesAlternateBanksAndTheNewestWinsAtPowerUp) {
  std::array<uint8_t, Nvm::kRegionSize> region;
  region.fill(Nvm::kErased);
  Nvm nvm(region.data());
  nvm.open(format_counting);
  const uint8_t a[] = {0xAA, 0xBB};
  ASSERT_TRUE(nvm.write(3, a, 2));
  EXPECT_EQ(nvm.current_bank(), 1u);
  const uint8_t b[] = {0x55};
  ASSERT_TRUE(nvm.write(9, b, 1));
  EXPECT_EQ(nvm.current_bank(), 0u);
  const std::vector<uint8_t> expected{0, 1, 2, 0xAA, 0xBB, 5, 6, 7, 8, 0x55};
  EXPECT_EQ(image_of(nvm), expected);

  Nvm after_reset(region.data());
  EXPECT_TRUE(after_reset.open(format_counting));
  EXPECT_EQ(image_of(after_reset), expected);
  EXPECT_EQ(after_reset.current_bank(), 0u);
}

TEST(FirmwareBankedNvm, OutOfBoundsWriteChangesNothing) {
  std::array<uint8_t, Nvm::kRegionSize> region;
  region.fill(Nvm::kErased);
  Nvm nvm(region.data());
  nvm.open(format_counting);
  const auto before = region;
  const uint8_t byte = 1;
  EXPECT_FALSE(nvm.write(kPayload, &byte, 1));
  EXPECT_FALSE(nvm.write(kPayload + 1, &byte, 0));
  EXPECT_EQ(region, before);
}

// A reset during a write: the bank being written is erased, partly programmed, or programmed
// without its header. Each leaves the old image at the next power-up.
TEST(FirmwareBankedNvm, AWriteCutShortLeavesTheOldImage) {
  std::array<uint8_t, Nvm::kRegionSize> region;
  region.fill(Nvm::kErased);
  Nvm nvm(region.data());
  nvm.open(format_counting);
  const uint8_t first[] = {0x11};
  ASSERT_TRUE(nvm.write(0, first, 1));
  const std::vector<uint8_t> old_image = image_of(nvm);
  const auto committed = region;
  const uint8_t second[] = {0x22};
  ASSERT_TRUE(nvm.write(0, second, 1));
  const auto finished = region;

  // The bank the second write used, at each stage of the write.
  const size_t bank = 0;
  const auto bank_offset = bank * Nvm::kBankSize;
  for (size_t programmed = 0; programmed <= Nvm::kBankSize; ++programmed) {
    region = committed;
    std::memset(region.data() + bank_offset, Nvm::kErased, Nvm::kBankSize);
    // Payload first, header last: `programmed` bytes of the finished bank in that order.
    const size_t payload_bytes = programmed < kPayload ? programmed : kPayload;
    std::memcpy(region.data() + bank_offset + Nvm::kHeaderSize, finished.data() + bank_offset + Nvm::kHeaderSize,
                payload_bytes);
    const size_t header_bytes = programmed - payload_bytes;
    if (header_bytes >= Nvm::kHeaderSize) continue;  // the write completed
    std::memcpy(region.data() + bank_offset, finished.data() + bank_offset, header_bytes);
    Nvm after_reset(region.data());
    EXPECT_TRUE(after_reset.open(format_counting));
    EXPECT_EQ(image_of(after_reset), old_image) << programmed << " bytes of the new bank programmed";
  }
}

TEST(FirmwareBankedNvm, ADamagedNewerBankFallsBackToTheOlder) {
  std::array<uint8_t, Nvm::kRegionSize> region;
  region.fill(Nvm::kErased);
  Nvm nvm(region.data());
  nvm.open(format_counting);
  const uint8_t value = 0x77;
  ASSERT_TRUE(nvm.write(5, &value, 1));
  region[1 * Nvm::kBankSize + Nvm::kHeaderSize + 2] ^= 0x01;  // a flipped bit in the newer bank
  Nvm after_reset(region.data());
  EXPECT_TRUE(after_reset.open(format_counting));
  EXPECT_EQ(image_of(after_reset), (std::vector<uint8_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

}  // namespace
}  // namespace motwin::firmware
