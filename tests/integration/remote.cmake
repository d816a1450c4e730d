# Remote sessions (issue 14, client side): short blips while the hand is
# inside the organ, the server stalled and then the client stalled. Domain 223.
viscera_integration_test(haptic_blip 223 blip_test.sh)
